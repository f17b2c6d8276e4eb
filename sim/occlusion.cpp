#include "sim/occlusion.hpp"

#include <Eigen/Geometry>
#include <algorithm>

namespace sg::sim {
namespace {

/// How far the panel is in front of the ball: 1 covering, 0 fully aside.
double cover(const OcclusionParams& p, double t) {
  double best = 0.0;
  for (const OcclusionEpisode& e : p.episodes) {
    const double end = e.start + e.duration;
    double c = 0.0;
    if (t >= e.start && t <= end) {
      c = 1.0;
    } else if (p.transition > 0 && t < e.start) {
      c = 1.0 - (e.start - t) / p.transition;
    } else if (p.transition > 0 && t > end) {
      c = 1.0 - (t - end) / p.transition;
    }
    best = std::max(best, std::clamp(c, 0.0, 1.0));
  }
  return best;
}

}  // namespace

bool fully_occluded_at(const OcclusionParams& params, double t) {
  return std::any_of(params.episodes.begin(), params.episodes.end(),
                     [&](const auto& e) { return t >= e.start && t <= e.start + e.duration; });
}

std::optional<std::array<Eigen::Vector3d, 4>> occluder_at(const OcclusionParams& p, double t,
                                                          const Eigen::Vector3d& ball,
                                                          const Eigen::Vector3d& viewpoint) {
  const double c = cover(p, t);
  if (c <= 0.0) return std::nullopt;
  const Eigen::Vector3d toward = (viewpoint - ball).normalized();
  const Eigen::Vector3d across = toward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d up = across.cross(toward).normalized();
  // Fully aside, the panel's near edge is half a width beyond the ball's line of sight.
  const Eigen::Vector3d centre = ball + p.standoff * toward + (1.0 - c) * p.width * across;
  const Eigen::Vector3d a = across * (p.width / 2), b = up * (p.height / 2);
  return std::array<Eigen::Vector3d, 4>{centre - a - b, centre + a - b, centre + a + b,
                                        centre - a + b};
}

}  // namespace sg::sim
