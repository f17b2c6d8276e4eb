// The product's driver core (arm::ArmDriver) against the C550 emulator in simulated time: the
// same rules as over sg-c550-sim's pseudo-terminal (tests/arm_driver, tests/integration/arm_test),
// deterministic and in milliseconds.
#include <gtest/gtest.h>

#include <cmath>

#include "arm_driver/arm_driver.hpp"
#include "sim/c550_controller.hpp"
#include "sim/c550_emulator.hpp"
#include "system/simulated_clock.hpp"
#include "system/simulated_line.hpp"
#include "tests/support/arm_commands.hpp"

namespace sg::system {
namespace {

using stereograsp::arm_status_t;

struct Rig {
  explicit Rig(arm::DriverSettings settings = {})
      : clock(0),
        controller(arm::ArmGeometry::a465()),
        emulator(controller),
        serial(emulator, clock),
        driver(arm::ArmGeometry::a465(), settings, [this] { return serial.connect(); }, clock) {}

  /// The commander's heartbeat (sender "test", as test::tool_down_move) every 0.2 s from `from`
  /// s: it stays present while its motion lasts, so the driver's watchdog lets the motion run.
  void keep_commanding(double from) {
    clock.every(
        0.2,
        [this](double) {
          stereograsp::arm_cmd_t h{};
          h.mode = stereograsp::arm_cmd_t::MODE_HEARTBEAT;
          h.speed = 0.5;
          h.sender = "test";
          driver.submit(h);
        },
        from);
  }

  /// Runs the driver until `end` s of simulated time.
  void run_until(double end) {
    clock.at(end, [this](double) { stop.request_stop(); });
    driver.run(stop.get_token());
  }
  int lines_starting(const std::string& verb) const {
    int n = 0;
    for (const std::string& line : emulator.executed_commands()) n += line.rfind(verb, 0) == 0;
    return n;
  }

  SimulatedClock clock;
  sim::C550Controller controller;
  sim::C550Emulator emulator;
  SimulatedLine serial;
  arm::ArmDriver driver;
  std::stop_source stop;
};

// A command sent once is executed once: one MA line, and the arm arrives at its target.
TEST(DriverInSimulatedTime, OneCommandOneMotion) {
  Rig r;
  const auto c = test::tool_down_move(1, 0.45, 0.0, 0.20, std::numbers::pi / 2);
  r.clock.at(1.0, [&](double) { r.driver.submit(c); });
  r.keep_commanding(1.0);
  r.run_until(8.0);
  EXPECT_EQ(r.lines_starting("MA "), 1);
  const arm_status_t s = r.driver.status().first;
  EXPECT_EQ(s.last_executed_sequence, 1);
  EXPECT_EQ(s.state, arm_status_t::STATE_IDLE);
  EXPECT_NEAR(s.tool_position[0], 0.45, 1e-3);
  EXPECT_NEAR(s.tool_position[2], 0.20, 1e-3);
  EXPECT_GT(s.interaction_time, 0.72);  // the controller's delay, on the simulated clock
  EXPECT_LT(s.interaction_time, 0.90);
}

// Latest wins: 100 commands arriving while an interaction is in flight give one more MA line,
// the newest, never a backlog.
TEST(DriverInSimulatedTime, BurstDuringAnInteractionKeepsOnlyTheNewest) {
  Rig r;
  r.clock.at(1.0, [&](double) {
    r.driver.submit(test::tool_down_move(1, 0.45, 0.0, 0.20, std::numbers::pi / 2));
  });
  r.clock.at(1.2, [&](double) {
    for (int k = 0; k < 100; ++k)
      r.driver.submit(test::tool_down_move(2 + k, 0.45, 0.001 * k, 0.20, std::numbers::pi / 2));
  });
  r.keep_commanding(1.0);
  r.run_until(10.0);
  EXPECT_EQ(r.lines_starting("MA "), 2);
  EXPECT_EQ(r.driver.status().first.last_executed_sequence, 101);
  EXPECT_NEAR(r.driver.status().first.tool_position[1], 0.099, 1e-3);
}

// The speed cap: a command at half speed goes out as SPEED 20 under max_speed = 0.2.
TEST(DriverInSimulatedTime, SpeedCapLimitsTheSpeedSent) {
  arm::DriverSettings settings;
  settings.max_speed = 0.2;
  Rig r(settings);
  r.clock.at(1.0, [&](double) {
    r.driver.submit(test::tool_down_move(1, 0.45, 0.0, 0.20, std::numbers::pi / 2));
  });
  r.run_until(12.0);
  EXPECT_EQ(r.lines_starting("SPEED 20"), 1);
  EXPECT_EQ(r.controller.speed_percent(), 20);
  EXPECT_DOUBLE_EQ(r.driver.status().first.speed, 0.2);
}

}  // namespace
}  // namespace sg::system
