#include "system/simulated_arm.hpp"

#include <array>
#include <stdexcept>
#include <utility>

#include "arm_driver/kinematics.hpp"

namespace sg::system {

namespace {

double checked_period(double rate) {
  if (!(rate > 0)) throw std::invalid_argument("simulated arm: status_rate must be positive");
  return 1.0 / rate;
}

}  // namespace

auth::LabKey trial_lab_key() {
  std::array<uint8_t, auth::LabKey::kSize> bytes;
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(0xA5 ^ (i * 7));
  return auth::LabKey(bytes);
}

SimulatedArm::SimulatedArm(const SimulatedArmParams& params, SimulatedClock& clock,
                           const auth::LabKey& key, BallAt ball_at)
    : clock_(clock),
      controller_(params.arm, params.c550),
      emulator_(controller_, params.driver.slave),
      line_(emulator_, clock,
            {params.baud, [this, ball_at = std::move(ball_at)](
                              double t) { emulator_.set_ball_centre(ball_at(t)); }}),
      driver_(
          params.arm, params.driver, [this] { return line_.connect(); }, clock),
      verifier_(key),
      status_rule_(checked_period(params.status_rate)) {}

void SimulatedArm::on_arm_command(const stereograsp::arm_cmd_t& command) {
  const auth::Verification v = verifier_.verify("ARM_COMMAND", command, clock_.utime());
  if (v.accepted()) {
    driver_.submit(command);
  } else {
    driver_.refuse(command, "unauthenticated: " + v.reason);
  }
}

std::optional<stereograsp::arm_status_t> SimulatedArm::status_due(double t) {
  auto [status, version] = driver_.status();
  if (!status_rule_.due(version, t)) return std::nullopt;
  status.utime = clock_.utime();
  return status;
}

sim::ArmState SimulatedArm::state(double t) const {
  sim::ArmState a;
  a.present = true;
  const Eigen::Isometry3d tool = controller_.tool_pose(t);
  a.tool_position = tool.translation();
  a.tool_rpy = arm::rpy_from_rotation(tool.rotation());
  a.gripper_opening = controller_.gripper_opening(t);
  a.holding_object = controller_.holding();
  return a;
}

}  // namespace sg::system
