#include "vision/ball_score.hpp"

#include <algorithm>
#include <limits>

namespace sg::vision {
namespace {

double square(double x) { return x * x; }

double shape_cost(const Candidate& c, const ScoringParams& p) {
  if (c.too_large) return p.max_cost;
  if (c.whole_disc) return 0.0;
  double cost = std::isfinite(c.fit_rms) ? square(c.fit_rms / p.fit_rms_scale) : 0.0;
  const double support = std::isfinite(c.support) ? c.support : 0.0;
  if (support < p.min_support / 2) return p.max_cost + 1;  // no circle in its outline
  if (support < p.min_support) cost += square((p.min_support - support) / 0.1);
  if (support >= p.fit_below_support && c.blob.minor_axis > 0) {
    const double excess =
        std::log(c.blob.major_axis / c.blob.minor_axis) - std::log(p.max_axis_ratio);
    if (excess > 0) cost += square(excess / p.axis_ratio_scale);
  }
  return cost;
}

}  // namespace

double candidate_cost(const Candidate& c, const ScoreContext& x, const ScoringParams& p) {
  if (!std::isfinite(c.centre.x) || !std::isfinite(c.centre.y) || !(c.radius > 0))
    return std::numeric_limits<double>::infinity();
  double cost = shape_cost(c, p);
  if (x.expected_radius && *x.expected_radius > 0)
    cost += square(std::log(c.radius / *x.expected_radius) / p.size_scale);
  if (x.expected_centre && x.motion_sigma > 0)
    cost += square(cv::norm(c.centre - *x.expected_centre) / x.motion_sigma);
  if (x.colour) {
    const cv::Vec4d& m = *x.colour;
    cost += square((c.mean_r - m[0]) / (p.colour_scale * m[1])) +
            square((c.mean_g - m[2]) / (p.colour_scale * m[3]));
  }
  if (c.clutter) cost += p.clutter_cost;
  if (x.largest_area > c.blob.area && c.blob.area > 0)
    cost += p.largest_weight * std::log(x.largest_area / c.blob.area);
  return cost;
}

}  // namespace sg::vision
