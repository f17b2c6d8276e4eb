#include "sim/stereo_rig.hpp"

#include <cmath>
#include <stdexcept>

namespace sg::sim {

std::array<vision::CameraModel, 2> make_rig(const RigParams& p) {
  if (!(p.baseline > 0)) throw std::invalid_argument("rig: baseline must be positive");
  if (!(p.toe_in > 0 && p.toe_in < M_PI / 2))
    throw std::invalid_argument("rig: toe_in must be between 0 and 90 degrees");
  const double distance = (p.baseline / 2) / std::tan(p.toe_in);
  const Eigen::Vector3d toward_rig(std::cos(p.pitch) * std::cos(p.azimuth),
                                   std::cos(p.pitch) * std::sin(p.azimuth), std::sin(p.pitch));
  const Eigen::Vector3d midpoint = p.target + distance * toward_rig;
  // Seen from behind the rig, looking at the target: right = forward x up.
  const Eigen::Vector3d forward = -toward_rig;
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d left_eye = midpoint - right * (p.baseline / 2);
  const Eigen::Vector3d right_eye = midpoint + right * (p.baseline / 2);
  return {vision::CameraModel::look_at(p.width, p.height, p.intrinsics, p.distortion, left_eye,
                                       p.target),
          vision::CameraModel::look_at(p.width, p.height, p.intrinsics, p.distortion, right_eye,
                                       p.target)};
}

}  // namespace sg::sim
