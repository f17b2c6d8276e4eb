#pragma once

/// The ball's colour as the tracker has learned it: running mean and standard deviation of the
/// mean normalized r and g (eq. 7) of regions confidently taken for the ball, an exponentially
/// weighted average that follows a slow lighting drift. It is a score term (ball_score.hpp), not
/// a threshold: the detector's ranges (eq. 8) stay as configured, so learning cannot widen what
/// is taken for the colour.
///
///     ColorModel model;
///     model.add(candidate.mean_r, candidate.mean_g);   // after each confident detection
///     if (auto m = model.estimate()) context.colour = m;  // mu_r, sigma_r, mu_g, sigma_g

#include <cmath>
#include <opencv2/core.hpp>
#include <optional>

namespace sg::vision {

class ColorModel {
 public:
  struct Params {
    double rate = 0.05;       ///< weight of a new sample (about 20 frames of memory)
    int min_samples = 10;     ///< no estimate before this many
    double min_sigma = 0.01;  ///< floor on the standard deviations
  };

  ColorModel() = default;
  explicit ColorModel(const Params& p) : p_(p) {}

  /// One confident detection's mean chromaticity; non-finite values are ignored.
  void add(double r, double g) {
    if (!std::isfinite(r) || !std::isfinite(g)) return;
    const double a = n_ == 0 ? 1.0 : std::max(p_.rate, 1.0 / (n_ + 1));
    update(mean_r_, var_r_, r, a);
    update(mean_g_, var_g_, g, a);
    ++n_;
  }

  /// mu_r, sigma_r, mu_g, sigma_g once min_samples were added.
  std::optional<cv::Vec4d> estimate() const {
    if (n_ < p_.min_samples) return std::nullopt;
    return cv::Vec4d(mean_r_, std::max(p_.min_sigma, std::sqrt(var_r_)), mean_g_,
                     std::max(p_.min_sigma, std::sqrt(var_g_)));
  }

  int samples() const { return n_; }
  void reset() { *this = ColorModel(p_); }

 private:
  static void update(double& mean, double& var, double x, double a) {
    const double d = x - mean;
    mean += a * d;
    var = (1 - a) * (var + a * d * d);
  }

  Params p_;
  double mean_r_ = 0, var_r_ = 0, mean_g_ = 0, var_g_ = 0;
  int n_ = 0;
};

}  // namespace sg::vision
