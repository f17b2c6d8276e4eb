#pragma once

#include <array>

#include "vision/camera_model.hpp"

namespace sg::sim {

/// Where the two cameras stand: the paper's rig by default (section 7, DESIGN §4) — two cameras
/// `baseline` apart, each turned `toe_in` toward the other so that their optical axes meet at
/// `target`, looking down at `pitch` from the side given by `azimuth`.
struct RigParams {
  Eigen::Vector3d target{0.45, 0.0, 0.10};  ///< where the optical axes meet, robot frame (m)
  double baseline = 0.50;                   ///< distance between the camera centres (m)
  double toe_in = 30.0 * M_PI / 180;        ///< each camera's turn toward the other (rad)
  double pitch = 40.0 * M_PI / 180;         ///< elevation of the rig seen from the target (rad)
  double azimuth = 0.0;                     ///< direction from the target to the rig, about Z
  int width = 640;
  int height = 480;
  vision::Intrinsics intrinsics{420.0, 420.0, 319.5, 239.5};
  vision::Distortion distortion;
};

/// The left and right cameras of the rig ([0] left, [1] right, as seen from behind the rig).
/// The distance from the rig's midpoint to the target follows from the baseline and toe-in:
/// (baseline / 2) / tan(toe_in).
std::array<vision::CameraModel, 2> make_rig(const RigParams& params);

}  // namespace sg::sim
