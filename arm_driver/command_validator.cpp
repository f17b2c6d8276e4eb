#include "arm_driver/command_validator.hpp"

#include <cmath>
#include <cstdio>

namespace sg::arm {
namespace {

using Cmd = stereograsp::arm_cmd_t;

bool all_finite(const double* values, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

std::string metres(const Eigen::Vector3d& p) {
  char text[80];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f) m", p.x(), p.y(), p.z());
  return text;
}

}  // namespace

ValidationResult CommandValidator::validate(const Cmd& command, const Joints& reference) {
  const auto last = last_sequence_.find(command.sender);
  if (last != last_sequence_.end() && command.sequence == last->second) {
    return {std::nullopt,
            "duplicate of command " + std::to_string(command.sequence) + " from '" +
                command.sender + "'",
            true};
  }
  if (last != last_sequence_.end() && command.sequence < last->second) {
    return reject("sequence " + std::to_string(command.sequence) + " from '" + command.sender +
                  "' is not newer than " + std::to_string(last->second));
  }
  last_sequence_[command.sender] = command.sequence;
  if (!std::isfinite(command.speed) || command.speed <= 0 || command.speed > 1) {
    return reject("speed " + std::to_string(command.speed) + " is outside (0, 1]");
  }
  if (command.gripper < Cmd::GRIPPER_KEEP || command.gripper > Cmd::GRIPPER_CLOSE) {
    return reject("unknown gripper action " + std::to_string(command.gripper));
  }
  ArmTarget target;
  target.sequence = command.sequence;
  target.mode = command.mode;
  target.gripper = command.gripper;
  target.speed = command.speed;
  target.source_utime = command.source_utime;
  target.sender = command.sender;
  switch (command.mode) {
    case Cmd::MODE_CARTESIAN: return cartesian(command, reference, std::move(target));
    case Cmd::MODE_JOINTS: return joints(command, std::move(target));
    case Cmd::MODE_GRIPPER_ONLY:
      if (command.gripper == Cmd::GRIPPER_KEEP) return reject("gripper-only command with KEEP");
      return {std::move(target), ""};
    case Cmd::MODE_HOME:
    case Cmd::MODE_STOP: return {std::move(target), ""};
    default: return reject("unknown mode " + std::to_string(command.mode));
  }
}

int64_t CommandValidator::last_sequence(const std::string& sender) const {
  const auto last = last_sequence_.find(sender);
  return last == last_sequence_.end() ? -1 : last->second;
}

ValidationResult CommandValidator::cartesian(const Cmd& command, const Joints& reference,
                                             ArmTarget target) const {
  if (!all_finite(command.position, 3) || !all_finite(command.orientation, 3)) {
    return reject("position or orientation is not finite");
  }
  const Eigen::Vector3d position(command.position[0], command.position[1], command.position[2]);
  const Eigen::Vector3d rpy(command.orientation[0], command.orientation[1],
                            command.orientation[2]);
  if (!geometry_.workspace.contains(position)) {
    return reject("target " + metres(position) + " is outside the workspace");
  }
  const IkResult ik = solve_nearest(geometry_, pose_from_xyz_rpy(position, rpy), reference);
  if (!ik.joints) return reject("target " + metres(position) + ": " + ik.error);
  target.joints = *ik.joints;
  return {std::move(target), ""};
}

ValidationResult CommandValidator::joints(const Cmd& command, ArmTarget target) const {
  if (!all_finite(command.joints, 6)) return reject("a joint angle is not finite");
  target.joints = Eigen::Map<const Joints>(command.joints);
  if (!within_limits(geometry_, target.joints)) return reject("joints outside their limits");
  const Eigen::Vector3d tool = forward_kinematics(geometry_, target.joints).translation();
  if (!geometry_.workspace.contains(tool)) {
    return reject("joints put the tool at " + metres(tool) + ", outside the workspace");
  }
  return {std::move(target), ""};
}

}  // namespace sg::arm
