#pragma once

/// Test helpers for the arm: a tool-down Cartesian ARM_COMMAND, and the message of an exception.
///
///     arm_cmd_t c = tool_down_move(1, 0.45, 0.0, 0.20, M_PI / 2);   // joint 6 near +90 degrees
///     EXPECT_EQ(message_of<LinkError>([&] { link.command("W2", t); }), "...");

#include <cstdint>
#include <numbers>
#include <string>

#include "stereograsp/arm_cmd_t.hpp"

namespace sg::test {

/// MODE_CARTESIAN to (x, y, z), the tool pointing down (roll pi) turned by `yaw`, at half speed,
/// gripper kept, from sender "test". Yaw pi/2 keeps joint 6 near +90 degrees for targets near the
/// X axis; yaw = atan2(y, x) + pi keeps it near zero anywhere.
inline stereograsp::arm_cmd_t tool_down_move(int64_t sequence, double x, double y, double z,
                                             double yaw) {
  stereograsp::arm_cmd_t c{};
  c.sequence = sequence;
  c.mode = stereograsp::arm_cmd_t::MODE_CARTESIAN;
  c.position[0] = x;
  c.position[1] = y;
  c.position[2] = z;
  c.orientation[0] = std::numbers::pi;
  c.orientation[2] = yaw;
  c.gripper = stereograsp::arm_cmd_t::GRIPPER_KEEP;
  c.speed = 0.5;
  c.sender = "test";
  return c;
}

/// The message of the exception `f` throws as E, or "<nothing thrown>".
template <typename E, typename F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "<nothing thrown>";
}

}  // namespace sg::test
