#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

namespace sg::vision {

/// The object's colour as ranges of normalized RGB (eq. 7): r = R/(R+G+B), g = G/(R+G+B),
/// b = B/(R+G+B), each within [min, max], and R+G+B at least `min_intensity` (below it the
/// chromaticity of a dark pixel is noise).
struct ColorThresholds {
  double r_min = 0.40, r_max = 1.0;
  double g_min = 0.0, g_max = 0.30;
  double b_min = 0.0, b_max = 0.30;
  int min_intensity = 60;  ///< floor on R+G+B (0..765)

  /// Ranges that hold the central `keep` fraction of a sample's pixels per band (so a highlight
  /// or an edge pixel in the sample does not widen them), learned from the pixels of `bgr`
  /// (CV_8UC3) inside `roi`, widened by `margin` on each side.
  static ColorThresholds learn(const cv::Mat& bgr, const cv::Rect& roi, double margin = 0.04,
                               double keep = 0.90);
};

/// The paper's threshold (eq. 8) on normalized RGB (eq. 7), in integer arithmetic with no
/// division: r >= r_min  <=>  2^16 R >= round(2^16 r_min) (R+G+B).
///
///     ColorDetector red(thresholds);
///     if (red.is_object(pixel)) ...     // pixel: const uint8_t* B, G, R
class ColorDetector {
 public:
  explicit ColorDetector(const ColorThresholds& t);

  bool is_object(const uint8_t* bgr) const {
    const int64_t b = bgr[0], g = bgr[1], r = bgr[2];
    const int64_t sum = b + g + r;
    if (sum < min_sum_) return false;
    // The bounds that reject most of a lab's pixels first: grey and wooden surfaces fail r >= r_min
    // or g <= g_max.
    return r * kOne >= r_lo_ * sum && g * kOne <= g_hi_ * sum && b * kOne <= b_hi_ * sum &&
           r * kOne <= r_hi_ * sum && g * kOne >= g_lo_ * sum && b * kOne >= b_lo_ * sum;
  }

  /// is_object() of `n` pixels at once: mask[i] = 1 for the object's colour, else 0. The same
  /// integer test in 32-bit lanes (every product fits: 255 x 2^16 and 2^16 x 765), with no
  /// branch, so the compiler vectorizes it: built with -O3 for AVX2 and for the baseline
  /// (target_clones, chosen when the program loads). Bit for bit is_object() (a test).
  void classify(const uint8_t* bgr, int n, uint8_t* mask) const;

  const ColorThresholds& thresholds() const { return t_; }

 private:
  static constexpr int64_t kOne = 1 << 16;
  ColorThresholds t_;
  int64_t r_lo_, r_hi_, g_lo_, g_hi_, b_lo_, b_hi_, min_sum_;
};

}  // namespace sg::vision
