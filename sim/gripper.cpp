#include "sim/gripper.hpp"

namespace sg::sim {

std::vector<Box> gripper_boxes(const ArmState& arm) {
  if (!arm.present) return {};
  Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
  tool.linear() = rotation_from_rpy(arm.tool_rpy);
  tool.translation() = arm.tool_position;
  Material grey;
  grey.albedo = {0.55, 0.55, 0.57};
  grey.specular = 0.0;  // matte: flat faces, and no highlight to compute per pixel
  auto part = [&](const Eigen::Vector3d& centre, const Eigen::Vector3d& half) {
    Box box;
    box.pose = tool * Eigen::Translation3d(centre);
    box.half_size = half;
    box.material = grey;
    return box;
  };
  const double finger_offset = arm.gripper_opening / 2 + 0.006;
  return {part({0, +finger_offset, -0.015}, {0.010, 0.006, 0.035}),
          part({0, -finger_offset, -0.015}, {0.010, 0.006, 0.035}),
          part({0, 0, -0.065}, {0.020, 0.065, 0.015}), part({0, 0, -0.120}, {0.025, 0.025, 0.040})};
}

}  // namespace sg::sim
