#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

namespace sg::sim {

/// One total occlusion: from `start` for `duration` seconds of scenario time the ball is hidden
/// from both cameras. The paper's system carries its track through up to 16 samples at 4 Hz (4 s).
struct OcclusionEpisode {
  double start = 0.0;
  double duration = 0.0;
};

/// The occluder: a flat panel that slides in front of the ball, stays while the episode lasts,
/// and slides out. While it slides (`transition` seconds before and after) the occlusion is
/// partial.
struct OcclusionParams {
  std::vector<OcclusionEpisode> episodes;
  double transition = 0.3;  ///< seconds to slide in, and to slide out
  double standoff = 0.10;   ///< distance from the ball's centre toward the cameras (m)
  double width = 0.26;      ///< panel size (m); wide enough to hide the ball from both cameras
  double height = 0.20;
};

/// The panel's four corners at time t, or nullopt when no episode is near. `ball` is the ball's
/// centre, `viewpoint` the midpoint of the cameras.
std::optional<std::array<Eigen::Vector3d, 4>> occluder_at(const OcclusionParams& params, double t,
                                                          const Eigen::Vector3d& ball,
                                                          const Eigen::Vector3d& viewpoint);

/// True when t lies inside an episode (the ball must then be hidden from both cameras).
bool fully_occluded_at(const OcclusionParams& params, double t);

}  // namespace sg::sim
