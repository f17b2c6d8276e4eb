#pragma once

#include <vector>

#include "sim/primitives.hpp"

namespace sg::sim {

/// The arm's end as the cameras see it, from SIM_ARM_STATE: robot base frame, metres, radians.
struct ArmState {
  bool present = false;  ///< false until the first SIM_ARM_STATE arrives
  Eigen::Vector3d tool_position = Eigen::Vector3d::Zero();  ///< tool centre point (fingertips)
  Eigen::Vector3d tool_rpy = Eigen::Vector3d::Zero();       ///< roll, pitch, yaw
  double gripper_opening = 0.08;                            ///< between the fingers (m)
  bool holding_object = false;                              ///< the ball is in the gripper
};

/// A simple grey parallel gripper: two fingers either side of the tool centre point along the
/// tool's y axis, a palm and a wrist behind them along -z (the tool's z axis points from the
/// wrist to the fingertips, the approach direction).
std::vector<Box> gripper_boxes(const ArmState& arm);

}  // namespace sg::sim
