#include "vision/stereo_match.hpp"

#include <cmath>

#include "vision/triangulation.hpp"

namespace sg::vision {
namespace {

double square(double x) { return x * x; }

/// The geometric part of a pair's cost; infinite when the point is behind a camera.
double pair_geometry_cost(const Candidate& l, const Candidate& r, const StereoCalibration& cal,
                          const StereoMatchParams& p, Eigen::Vector3d& position) {
  const Triangulated t =
      triangulate_linear(cal.left, {l.centre.x, l.centre.y}, cal.right, {r.centre.x, r.centre.y});
  if (t.behind_camera || !t.position.allFinite()) return std::numeric_limits<double>::infinity();
  position = t.position;
  double cost = square(t.reprojection_error / p.epipolar_sigma);
  if (p.ball_radius > 0) {
    const double expected[2] = {apparent_radius(cal.left, t.position, p.ball_radius),
                                apparent_radius(cal.right, t.position, p.ball_radius)};
    const double seen[2] = {l.radius, r.radius};
    for (int i = 0; i < 2; ++i) {
      if (!(expected[i] > 0) || !(seen[i] > 0)) return std::numeric_limits<double>::infinity();
      cost += square(std::log(seen[i] / expected[i]) / p.size_scale);
    }
  }
  return cost;
}

}  // namespace

double apparent_radius(const CameraModel& camera, const Eigen::Vector3d& world, double radius) {
  const Eigen::Vector3d c = camera.to_camera(world);
  const double d2 = c.squaredNorm() - radius * radius;
  if (c.z() <= 0 || d2 <= 0) return std::nan("");
  const double f = (camera.intrinsics().fx + camera.intrinsics().fy) / 2;
  return f * radius / std::sqrt(d2);
}

StereoMatch match_stereo(const Detection& left, const Detection& right,
                         const StereoCalibration& calibration, const ScoringParams& scoring,
                         const StereoMatchParams& p) {
  StereoMatch best;
  best.cost = p.max_cost;
  for (int i = 0; i < left.count; ++i) {
    const Candidate& l = left.candidates[static_cast<size_t>(i)];
    if (!(l.cost <= scoring.max_cost)) continue;
    for (int j = 0; j < right.count; ++j) {
      const Candidate& r = right.candidates[static_cast<size_t>(j)];
      if (!(r.cost <= scoring.max_cost) || !(l.cost + r.cost < best.cost)) continue;
      Eigen::Vector3d position = Eigen::Vector3d::Zero();
      const double cost = l.cost + r.cost + pair_geometry_cost(l, r, calibration, p, position);
      if (cost <= best.cost) best = StereoMatch{i, j, cost, position};
    }
  }
  if (!best.found()) best.cost = std::numeric_limits<double>::infinity();
  return best;
}

}  // namespace sg::vision
