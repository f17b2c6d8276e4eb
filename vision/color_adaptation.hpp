#pragma once

/// The detector's colour ranges (eq. 8) narrowed to the ball as it is seen: each band of
/// normalized RGB (eq. 7) is cut to the central pixels of confidently found, fully visible ball
/// images, and follows a lighting drift — within the configured ranges, never beyond them.
///
/// For each band (r, g, b) the pixels within `inner` radii of the ball's centre (every other one,
/// on a coarser grid for a near ball: at most about 300) give the
/// `quantile` and 1 - `quantile` values q_lo, q_hi of one frame; their exponentially weighted
/// averages (weight `rate`) L, H give the band
///
///     [max(lo_configured, L - margin), min(hi_configured, H + margin)],
///
/// widened within the configured band to at least `min_width`. An orange beside the ball
/// (r ~ 0.5, g ~ 0.3) or a maroon jacket lies inside the default ranges but outside the ball's
/// learned ones, so it no longer merges with the ball or starts a false track while the ball is
/// hidden. forget() returns to the configured ranges (the tracker calls it when it forgets the
/// ball's size: after a long absence the light may have changed).
///
///     ColorAdaptation adapt(params.color, params.adaptation);
///     if (confident && fully_visible && adapt.learn(bgr, centre, radius))
///       detector = ColorDetector(adapt.thresholds());
///
/// learn() allocates nothing after construction.

#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "vision/color_detector.hpp"

namespace sg::vision {

struct ColorAdaptationParams {
  bool enabled = true;
  double inner = 0.7;       ///< of the radius: the disc whose pixels are sampled (no edge pixels)
  double quantile = 0.02;   ///< each side, of one frame's sampled pixels
  double rate = 0.1;        ///< weight of a new frame (about 10 frames of memory)
  double margin = 0.06;     ///< added on each side of the learned band
  double min_width = 0.12;  ///< a band is never narrower (within the configured one)
  int min_samples = 5;      ///< frames learned before the ranges are narrowed
  int min_pixels = 30;      ///< a frame with fewer sampled pixels is not learned from
};

class ColorAdaptation {
 public:
  ColorAdaptation(const ColorThresholds& configured, const ColorAdaptationParams& params);

  /// Learns from the ball's image at `centre`, `radius` px in `bgr` (CV_8UC3); true when the
  /// ranges changed. Non-finite or out-of-image arguments are ignored (false).
  bool learn(const cv::Mat& bgr, const cv::Point2d& centre, double radius);

  /// Back to the configured ranges; true when they had been narrowed.
  bool forget();

  /// The ranges to detect with: the configured ones until min_samples frames were learned.
  const ColorThresholds& thresholds() const { return current_; }
  int samples() const { return samples_; }

 private:
  bool sample(const cv::Mat& bgr, const cv::Point2d& centre, double radius);
  void update_current();

  ColorThresholds configured_, current_;
  ColorAdaptationParams p_;
  // r, g, b of one frame's `count_` sampled pixels (first R, G, B, then divided by sum_)
  std::array<std::vector<float>, 3> pixels_;
  std::vector<float> sum_;  // R+G+B of each sampled pixel
  size_t count_ = 0;
  std::array<double, 3> low_{}, high_{};  // L, H per band
  int samples_ = 0;
};

}  // namespace sg::vision
