#pragma once

/// The arm as an in-process trial has it: the C550 (sim::C550Controller and the serial emulator
/// sg-c550-sim runs) on a SimulatedLine, driven by sg-arm-driver's own core (arm::ArmDriver),
/// which checks each ARM_COMMAND's signature with the lab key as sg-arm-driver does and publishes
/// ARM_STATUS on a change or once a period, as its loop does. The grasp trial and the
/// calibration trial share it, so both drive the very bytes the lab's driver sends.
///
///     SimulatedClock clock(kTrialEpochUtime);
///     SimulatedArm arm(params, clock, key, [&](double t) { return world.ball_at(t); });
///     clock.every(0.005, [&](double t) {                   // sg-arm-driver's loop
///       if (auto status = arm.status_due(t)) deliver(*status);
///     });
///     ... on ARM_COMMAND: arm.on_arm_command(command);      // verified, then submitted
///     arm.run(stop.get_token());                            // its waits run the world
///
/// Lifecycle: constructed with the controller powered up (holding the ball when
/// c550.start_holding); run() connects the driver and serves until `stop`; it must outlive run().

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <stop_token>
#include <string>

#include "arm_driver/arm_driver.hpp"
#include "auth/command_auth.hpp"
#include "auth/lab_key.hpp"
#include "common/change_or_period.hpp"
#include "sim/c550_controller.hpp"
#include "sim/c550_emulator.hpp"
#include "sim/gripper.hpp"
#include "system/simulated_clock.hpp"
#include "system/simulated_line.hpp"

namespace sg::system {

/// sg-arm-driver's loop handles the bus for 5 ms, then publishes ARM_STATUS when due: the period at
/// which a trial calls SimulatedArm::status_due.
inline constexpr double kDriverLoopPeriod = 0.005;

/// The lab key of the in-process trials: fixed bytes (a trial signs and checks every command as
/// the lab does; there is no secret in simulated time).
auth::LabKey trial_lab_key();

/// The arm's parts and their settings.
struct SimulatedArmParams {
  arm::ArmGeometry arm = arm::ArmGeometry::a465();
  sim::C550Params c550;
  arm::DriverSettings driver;  ///< sg-arm-driver's settings (timing, polls, retries)
  int baud = 38400;            ///< the serial line
  double status_rate = 20.0;   ///< Hz: ARM_STATUS at rest (> 0)
};

class SimulatedArm {
 public:
  /// Where the world's ball is at time t (the controller grasps it there on a CLOSE).
  using BallAt = std::function<Eigen::Vector3d(double t)>;

  /// Throws std::invalid_argument for a bad controller parameter or status rate.
  SimulatedArm(const SimulatedArmParams& params, SimulatedClock& clock, const auth::LabKey& key,
               BallAt ball_at);
  SimulatedArm(const SimulatedArm&) = delete;
  SimulatedArm& operator=(const SimulatedArm&) = delete;

  /// sg-arm-driver's subscription: a command whose signature the lab key accepts is submitted,
  /// any other refused ("unauthenticated: ...") as the driver refuses it.
  void on_arm_command(const stereograsp::arm_cmd_t& command);
  /// sg-arm-driver's loop at time t: ARM_STATUS (stamped now) when it changed or a period passed.
  std::optional<stereograsp::arm_status_t> status_due(double t);
  /// The driver's worker until `stop`; every wait it makes runs the simulated world.
  void run(std::stop_token stop) { driver_.run(stop); }

  /// The arm as sg-c550-sim announces it on SIM_ARM_STATE (for the rendered gripper).
  sim::ArmState state(double t) const;
  const sim::C550Controller& controller() const { return controller_; }
  const sim::C550Emulator& emulator() const { return emulator_; }
  const SimulatedLine& line() const { return line_; }
  const arm::ArmDriver& driver() const { return driver_; }

 private:
  SimulatedClock& clock_;
  sim::C550Controller controller_;
  sim::C550Emulator emulator_;
  SimulatedLine line_;
  arm::ArmDriver driver_;
  auth::CommandVerifier verifier_;
  ChangeOrPeriod status_rule_;
};

}  // namespace sg::system
