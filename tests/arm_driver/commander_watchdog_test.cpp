// One commander and the watchdog (issue 15): the driver core (ArmDriver, real code) against the
// C550 emulator over the simulated serial line, in simulated time (system/simulated_clock.hpp):
// a second sender refused while the first holds the lease, take-over, STOP from anyone, release,
// expiry, the watchdog's stop of a moving arm and its deadline, duplicates executed once, and a
// non-holder's heartbeats that do not keep the holder alive.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "arm_driver/arm_driver.hpp"
#include "sim/c550_controller.hpp"
#include "sim/c550_emulator.hpp"
#include "system/simulated_clock.hpp"
#include "system/simulated_line.hpp"
#include "tests/support/arm_commands.hpp"

namespace sg::arm {
namespace {

using Cmd = stereograsp::arm_cmd_t;
using Status = stereograsp::arm_status_t;

const std::string kA = "sg-grasp@lab1:412";
const std::string kB = "sg-arm-ctl@lab2:77";
constexpr double kTimeout = 1.6;       // DriverSettings' default commander_timeout
constexpr double kInteraction = 0.84;  // the longest controller interaction (C550Params)

/// A tool-down move from `sender`; at `speed` 0.1 the move from READY to (0.45, 0, 0.2) lasts
/// several seconds, long enough for the watchdog to catch it.
Cmd move(const std::string& sender, int64_t sequence, double y = 0.0, double speed = 0.5) {
  Cmd c = test::tool_down_move(sequence, 0.45, y, 0.20, std::numbers::pi / 2);
  c.sender = sender;
  c.speed = speed;
  return c;
}

/// A command of `mode` that carries no motion (STOP, HEARTBEAT, RELEASE) from `sender`.
Cmd bare(const std::string& sender, int8_t mode, int64_t sequence) {
  Cmd c{};
  c.sequence = sequence;
  c.mode = mode;
  c.gripper = Cmd::GRIPPER_KEEP;
  c.speed = 0.5;
  c.sender = sender;
  return c;
}

/// The driver on the emulator in simulated time, started at t = 0.
struct Rig {
  Rig()
      : clock(0),
        controller(ArmGeometry::a465()),
        emulator(controller),
        line(emulator, clock),
        driver(
            ArmGeometry::a465(), DriverSettings{}, [this] { return line.connect(); }, clock) {
    // Samples the emulator's log every 10 ms: when each line first appeared.
    clock.every(0.01, [this](double t) {
      const auto lines = emulator.executed_commands();
      for (size_t i = seen.size(); i < lines.size(); ++i) seen.push_back({lines[i], t});
    });
  }

  /// At `t`, submits `c` (the driver's answer goes to `outcomes`, or for a heartbeat to
  /// `heartbeat_outcomes`).
  void at(double t, Cmd c) {
    clock.at(t, [this, c](double) {
      (c.mode == Cmd::MODE_HEARTBEAT ? heartbeat_outcomes : outcomes).push_back(driver.submit(c));
    });
  }
  /// From `from` to `to`, a heartbeat of `sender` (sequence `sequence`) every 0.2 s.
  void heartbeats(const std::string& sender, int64_t sequence, double from, double to) {
    for (double t = from; t <= to + 1e-9; t += 0.2)
      at(t, bare(sender, Cmd::MODE_HEARTBEAT, sequence));
  }
  /// At `t`, keeps a copy of the status in `snapshots`.
  void snapshot(double t) {
    clock.at(t, [this](double) { snapshots.push_back(driver.status().first); });
  }
  void run_until(double end) {
    clock.at(end, [this](double) { stop.request_stop(); });
    driver.run(stop.get_token());
  }
  int lines_starting(const std::string& verb) const {
    int n = 0;
    for (const std::string& l : emulator.executed_commands()) n += l.rfind(verb, 0) == 0;
    return n;
  }
  /// When the first line starting with `verb` was seen (10 ms resolution), -1 when never.
  double first_seen(const std::string& verb) const {
    for (const auto& [l, t] : seen) {
      if (l.rfind(verb, 0) == 0) return t;
    }
    return -1;
  }
  Status status() const { return driver.status().first; }
  double tool_x() const { return status().tool_position[0]; }

  system::SimulatedClock clock;
  sim::C550Controller controller;
  sim::C550Emulator emulator;
  system::SimulatedLine line;
  ArmDriver driver;
  std::stop_source stop;
  std::vector<std::pair<std::string, double>> seen;
  std::vector<Submission> outcomes;
  std::vector<Submission> heartbeat_outcomes;
  std::vector<Status> snapshots;
};

// While A holds the lease (heard 0.2 s ago), B's move is refused with A named, and changes
// nothing A is judged by; A's move alone reaches the controller.
TEST(CommanderLeaseInDriver, SecondSenderIsRefusedWhileTheFirstHoldsTheLease) {
  Rig r;
  r.at(1.0, move(kA, 1));
  r.at(1.2, move(kB, 50, 0.1));
  r.heartbeats(kA, 1, 1.4, 4.0);
  r.run_until(5.0);
  ASSERT_EQ(r.outcomes.size(), 2u);
  ASSERT_EQ(r.heartbeat_outcomes.size(), 14u);
  EXPECT_EQ(r.heartbeat_outcomes.back().outcome, Submission::kLease);
  EXPECT_EQ(r.outcomes[0].outcome, Submission::kQueued);
  EXPECT_EQ(r.outcomes[1].outcome, Submission::kRefused);
  EXPECT_EQ(r.outcomes[1].reason,
            "arm commanded by 'sg-grasp@lab1:412' (heard 0.2 s ago); sg-arm-ctl --take-over "
            "takes it");
  const Status s = r.status();
  EXPECT_EQ(s.commander, kA);
  EXPECT_EQ(s.last_received_sequence, 1);
  EXPECT_EQ(s.last_executed_sequence, 1);
  EXPECT_EQ(s.last_rejected_sequence, 50);
  EXPECT_EQ(s.rejection_reason, r.outcomes[1].reason);
  EXPECT_EQ(r.lines_starting("MA "), 1);
  EXPECT_NEAR(s.tool_position[1], 0.0, 1e-3);  // A's target, not B's
}

// B with take_over gets the lease and its move runs after A's; A is refused afterwards.
TEST(CommanderLeaseInDriver, TakeOverHandsTheArmToTheNewSender) {
  Rig r;
  r.at(1.0, move(kA, 1));
  Cmd taking = move(kB, 50, 0.1);
  taking.take_over = true;
  r.at(1.2, taking);
  r.at(1.4, move(kA, 2));
  r.heartbeats(kB, 50, 1.6, 5.0);
  r.run_until(6.0);
  EXPECT_EQ(r.outcomes[1].outcome, Submission::kQueued);
  EXPECT_EQ(r.outcomes[2].outcome, Submission::kRefused);
  const Status s = r.status();
  EXPECT_EQ(s.commander, kB);
  EXPECT_EQ(s.last_received_sequence, 50);
  EXPECT_EQ(s.last_executed_sequence, 50);
  EXPECT_EQ(r.lines_starting("MA "), 2);
  EXPECT_NEAR(s.tool_position[1], 0.1, 1e-3);
}

// A STOP from B, who does not hold the lease, is obeyed (ABORT reaches the controller) and
// leaves A holding it.
TEST(CommanderLeaseInDriver, StopFromAnyoneIsObeyed) {
  Rig r;
  r.at(1.0, move(kA, 1, 0.0, 0.1));
  r.heartbeats(kA, 1, 1.2, 6.0);
  r.at(3.0, bare(kB, Cmd::MODE_STOP, 70));
  r.run_until(6.0);
  ASSERT_EQ(r.outcomes.size(), 2u);
  EXPECT_EQ(r.outcomes[1].outcome, Submission::kQueued);
  EXPECT_EQ(r.lines_starting("ABORT"), 1);
  EXPECT_GE(r.first_seen("ABORT"), 3.0);
  EXPECT_LT(r.first_seen("ABORT"), 3.0 + kInteraction);
  const Status s = r.status();
  EXPECT_EQ(s.commander, kA);
  EXPECT_EQ(s.last_received_sequence, 1);  // the commander's, not B's
  EXPECT_EQ(s.last_executed_sequence, 70);
  EXPECT_EQ(s.state, Status::STATE_IDLE);
  EXPECT_GT(std::abs(s.tool_position[0] - 0.45) + std::abs(s.tool_position[2] - 0.20), 0.01)
      << "stopped short of the target";
}

// A's MODE_RELEASE frees the lease (B's release before it is refused); B then commands
// without take_over. Heartbeats and releases consume no sequence: A's next sequence is 2.
TEST(CommanderLeaseInDriver, ReleaseFreesTheLeaseForTheNextSender) {
  Rig r;
  r.at(1.0, move(kA, 1));
  r.heartbeats(kA, 1, 1.2, 3.0);
  r.at(3.1, bare(kB, Cmd::MODE_RELEASE, 9));
  r.snapshot(3.15);
  r.at(3.2, bare(kA, Cmd::MODE_RELEASE, 1));
  r.snapshot(3.25);
  r.at(3.3, move(kB, 50, 0.1));
  r.heartbeats(kB, 50, 3.5, 7.0);
  r.run_until(8.0);
  ASSERT_EQ(r.snapshots.size(), 2u);
  EXPECT_EQ(r.snapshots[0].commander, kA);
  EXPECT_EQ(r.snapshots[0].last_rejected_sequence, -1);  // a refused release records nothing
  EXPECT_EQ(r.snapshots[1].commander, "");
  EXPECT_EQ(r.snapshots[1].last_received_sequence, 1);
  const Status s = r.status();
  EXPECT_EQ(s.commander, kB);
  EXPECT_EQ(s.last_executed_sequence, 50);
  EXPECT_EQ(r.lines_starting("MA "), 2);
  EXPECT_EQ(s.watchdog, "");
}

// A holder silent at rest loses the lease after the timeout; nothing is stopped.
TEST(CommanderLeaseInDriver, SilentHolderAtRestLosesTheLeaseQuietly) {
  Rig r;
  r.at(1.0, bare(kA, Cmd::MODE_HEARTBEAT, 0));
  r.snapshot(1.0 + kTimeout - 0.05);
  r.snapshot(1.0 + kTimeout + 0.05);
  r.run_until(4.0);
  ASSERT_EQ(r.snapshots.size(), 2u);
  EXPECT_EQ(r.snapshots[0].commander, kA);
  EXPECT_EQ(r.snapshots[1].commander, "");
  EXPECT_EQ(r.status().watchdog, "");
  EXPECT_EQ(r.lines_starting("ABORT"), 0);
}

// The watchdog: A's slow move, heartbeats until t = 2 s, then silence. ABORT reaches the
// controller no later than the last heartbeat + timeout + one interaction; the gripper is not
// touched, last_executed_sequence stays A's, the arm holds where it stopped, and ARM_STATUS
// says why.
TEST(Watchdog, StopsAMovingArmWhenItsCommanderFallsSilent) {
  Rig r;
  r.at(1.0, move(kA, 1, 0.0, 0.1));
  r.heartbeats(kA, 1, 1.2, 2.0);
  r.snapshot(7.0);
  r.run_until(9.0);
  const double abort_at = r.first_seen("ABORT");
  ASSERT_GT(abort_at, 0) << "no ABORT";
  std::printf("ABORT seen at %.2f s, 2.00 s + %.2f s after the last heartbeat\n", abort_at,
              abort_at - 2.0);
  EXPECT_GE(abort_at, 2.0 + kTimeout);
  EXPECT_LE(abort_at, 2.0 + kTimeout + kInteraction);
  EXPECT_EQ(r.lines_starting("ABORT"), 1);
  EXPECT_EQ(r.lines_starting("OPEN"), 0);
  EXPECT_EQ(r.lines_starting("CLOSE"), 0);
  const Status s = r.status();
  EXPECT_EQ(s.watchdog.rfind("stopped: 'sg-grasp@lab1:412' silent for 1.6", 0), 0u) << s.watchdog;
  EXPECT_EQ(s.error, s.watchdog);
  EXPECT_EQ(s.commander, "");
  EXPECT_EQ(s.last_executed_sequence, 1);
  EXPECT_EQ(s.last_rejected_sequence, -1);
  EXPECT_EQ(s.state, Status::STATE_IDLE);
  ASSERT_EQ(r.snapshots.size(), 1u);
  for (int i = 0; i < 3; ++i)  // held still from 7 s to 9 s, short of the target
    EXPECT_NEAR(s.tool_position[i], r.snapshots[0].tool_position[i], 1e-9) << i;
  EXPECT_GT(std::abs(s.tool_position[0] - 0.45) + std::abs(s.tool_position[2] - 0.20), 0.01);
}

// The same slow move with heartbeats all along: no ABORT, the arm arrives, no watchdog.
TEST(Watchdog, LeavesTheArmAloneWhileHeartbeatsCome) {
  Rig r;
  r.at(1.0, move(kA, 1, 0.0, 0.1));
  r.heartbeats(kA, 1, 1.2, 20.0);
  r.run_until(20.0);
  EXPECT_EQ(r.lines_starting("ABORT"), 0);
  const Status s = r.status();
  EXPECT_EQ(s.watchdog, "");
  EXPECT_EQ(s.state, Status::STATE_IDLE);
  EXPECT_NEAR(s.tool_position[0], 0.45, 1e-3);
  EXPECT_NEAR(s.tool_position[2], 0.20, 1e-3);
}

// B's heartbeats do not keep A's lease alive: A falls silent after its move and the watchdog
// stops the arm on A's deadline; B gets only a free lease, after the stop.
TEST(Watchdog, HeartbeatsFromANonHolderDoNotRefreshTheHolder) {
  Rig r;
  r.at(1.0, move(kA, 1, 0.0, 0.1));
  r.heartbeats(kB, 0, 1.1, 5.0);
  r.snapshot(4.0);
  r.run_until(7.0);
  const double abort_at = r.first_seen("ABORT");
  EXPECT_GE(abort_at, 1.0 + kTimeout);
  EXPECT_LE(abort_at, 1.0 + kTimeout + kInteraction);
  ASSERT_FALSE(r.heartbeat_outcomes.empty());
  EXPECT_EQ(r.heartbeat_outcomes[0].outcome, Submission::kRefused);
  EXPECT_EQ(r.heartbeat_outcomes.back().outcome, Submission::kLease);  // the free lease, later
  const Status s = r.status();
  EXPECT_EQ(s.watchdog.rfind("stopped: 'sg-grasp@lab1:412' silent for", 0), 0u) << s.watchdog;
  ASSERT_EQ(r.snapshots.size(), 1u);
  EXPECT_EQ(r.snapshots[0].commander, kB);  // B's heartbeats took the lease A lost
  EXPECT_EQ(s.last_rejected_sequence, -1);  // refused heartbeats record nothing
}

// A resend of the same sequence (sg-grasp fearing a lost command) is a duplicate: one MA, no
// rejection; an older sequence is still rejected.
TEST(Duplicates, TheSameSequenceIsExecutedOnce) {
  Rig r;
  r.at(1.0, move(kA, 5));
  r.at(1.3, move(kA, 5));  // while its interaction is in flight
  r.at(3.0, move(kA, 5));  // after it ran
  r.at(3.2, move(kA, 4));
  r.heartbeats(kA, 5, 1.2, 4.0);
  r.run_until(5.0);
  EXPECT_EQ(r.outcomes[1].outcome, Submission::kDuplicate);
  EXPECT_EQ(r.outcomes[2].outcome, Submission::kDuplicate);
  EXPECT_EQ(r.outcomes[3].outcome, Submission::kRejected);
  EXPECT_EQ(r.lines_starting("MA "), 1);
  const Status s = r.status();
  EXPECT_EQ(s.last_executed_sequence, 5);
  EXPECT_EQ(s.last_received_sequence, 5);
  EXPECT_EQ(s.last_rejected_sequence, 4);
  EXPECT_EQ(s.rejection_reason, "sequence 4 from 'sg-grasp@lab1:412' is not newer than 5");
}

// driver_start_utime is the start time given, else the clock's at construction.
TEST(CommanderLeaseInDriver, ReportsTheDriverStartTime) {
  system::SimulatedClock clock(1'700'000'000'000'000);
  DriverSettings settings;
  ArmDriver implicit(
      ArmGeometry::a465(), settings, [] { return nullptr; }, clock);
  EXPECT_EQ(implicit.status().first.driver_start_utime, 1'700'000'000'000'000);
  settings.start_utime = 42;
  ArmDriver given(
      ArmGeometry::a465(), settings, [] { return nullptr; }, clock);
  EXPECT_EQ(given.status().first.driver_start_utime, 42);
}

}  // namespace
}  // namespace sg::arm
