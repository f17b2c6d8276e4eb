// The driver core (ArmDriver, real code) against the C550 emulator model (sim/), both in this
// process: the emulator runs in real (steady_clock) time behind a ByteStream adapter, with a short
// interaction delay so that the tests are quick. Checks a Cartesian move, the gripper, a rejected
// target, latest-wins under a burst of commands, and reconnection after the line goes down (with
// a heartbeat going, as from a live commander: the watchdog stops an abandoned arm).

#include "arm_driver/arm_driver.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "arm_driver/rapl.hpp"
#include "sim/c550_controller.hpp"
#include "sim/c550_emulator.hpp"
#include "tests/support/arm_commands.hpp"
#include "tests/support/wait.hpp"

namespace sg::arm {
namespace {

using Cmd = stereograsp::arm_cmd_t;
using Status = stereograsp::arm_status_t;
using Clock = std::chrono::steady_clock;
using sim::C550Controller;
using sim::C550Emulator;
using sim::C550Params;

constexpr double kPi = std::numbers::pi;
constexpr auto kPatience = std::chrono::seconds(10);

/// Controller parameters with a short interaction delay of `delay` seconds.
C550Params quick(double delay) {
  C550Params p;
  p.delay_min = delay;
  p.delay_max = delay;
  return p;
}

/// The controller and every emulator session on it, in real time; shared by the test thread and
/// the driver's worker (every access under `mutex`). Each open() is a new session (a fresh
/// emulator in ACI mode, as after plugging the cable back in) on the same controller.
class Bench {
 public:
  /// Decides, from the text the host has written on the current line (up to and including its
  /// CR), whether the line goes down right now.
  using DropTrigger = std::function<bool(const std::string& line)>;

  explicit Bench(C550Params params) : controller_(ArmGeometry::a465(), params) {}

  /// The DeviceOpener: throws LinkDown while the device is unavailable.
  std::unique_ptr<ByteStream> open();

  /// Seconds since the bench started; call under `mutex`, so that times never go backwards.
  double now() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  /// Every command line the controller received, over all sessions, in order.
  std::vector<std::string> executed() const {
    std::lock_guard lock(mutex);
    std::vector<std::string> all;
    for (const auto& e : emulators_) {
      const auto lines = e->executed_commands();
      all.insert(all.end(), lines.begin(), lines.end());
    }
    return all;
  }
  /// The lines of executed() that start with `prefix`.
  std::vector<std::string> executed_starting(const std::string& prefix) const {
    std::vector<std::string> out;
    for (const std::string& line : executed()) {
      if (line.starts_with(prefix)) out.push_back(line);
    }
    return out;
  }
  int sessions() const {
    std::lock_guard lock(mutex);
    return static_cast<int>(emulators_.size());
  }
  Eigen::Vector3d tool_position() {
    std::lock_guard lock(mutex);
    pump_retired(now());
    return controller_.tool_pose(now()).translation();
  }
  double gripper_opening() {
    std::lock_guard lock(mutex);
    pump_retired(now());
    return controller_.gripper_opening(now());
  }

  /// The open line goes down: its next call throws LinkDown.
  void drop_line() { ++generation_; }
  /// The line goes down as soon as `trigger` says so, once.
  void drop_when(DropTrigger trigger) {
    std::lock_guard lock(mutex);
    trigger_ = std::move(trigger);
  }
  /// While false, open() throws LinkDown (the cable is out).
  void set_available(bool available) { available_ = available; }

  mutable std::mutex mutex;

 private:
  /// Sessions whose line has gone still finish what the controller received (a motion command is
  /// acted on after the interaction delay); their output goes nowhere. Call under `mutex`.
  void pump_retired(double t) {
    for (size_t i = 0; i + 1 < emulators_.size(); ++i) emulators_[i]->take_output(t);
  }

  friend class EmulatedLine;

  C550Controller controller_;
  Clock::time_point start_ = Clock::now();
  std::vector<std::unique_ptr<C550Emulator>> emulators_;
  std::atomic<int> generation_{0};
  std::atomic<bool> available_{true};
  DropTrigger trigger_;
};

/// One session's serial line: bytes written are fed to the emulator at the current time; bytes
/// read are whatever the emulator's output has come due. Throws LinkDown once the bench drops it.
class EmulatedLine final : public ByteStream {
 public:
  EmulatedLine(Bench& bench, C550Emulator& emulator)
      : bench_(bench), emulator_(emulator), generation_(bench.generation_) {}

  void write(std::span<const uint8_t> bytes) override {
    check_up();
    std::lock_guard lock(bench_.mutex);
    bench_.pump_retired(bench_.now());
    for (const uint8_t byte : bytes) {
      emulator_.feed(byte, bench_.now());
      line_.push_back(static_cast<char>(byte));
      if (bench_.trigger_ && bench_.trigger_(line_)) {
        bench_.trigger_ = nullptr;
        ++bench_.generation_;
        return;  // the rest of these bytes are lost with the line
      }
      if (byte == '\r') line_.clear();
    }
  }

  std::optional<uint8_t> read_byte(std::chrono::microseconds timeout) override {
    const auto deadline = Clock::now() + timeout;
    for (;;) {
      check_up();
      if (!received_.empty()) {
        const uint8_t byte = received_.front();
        received_.pop_front();
        return byte;
      }
      double next = 0;
      {
        std::lock_guard lock(bench_.mutex);
        const double t = bench_.now();
        bench_.pump_retired(t);
        for (const uint8_t byte : emulator_.take_output(t)) received_.push_back(byte);
        next = emulator_.next_output_time() - t;
      }
      if (!received_.empty()) continue;
      const auto now = Clock::now();
      if (now >= deadline) return std::nullopt;
      // Sleep until the next output is due, the deadline, or 2 ms (to notice a drop).
      auto wake = std::min(deadline, now + std::chrono::milliseconds(2));
      if (next < 0.002)
        wake = std::min(wake, now + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(next)));
      std::this_thread::sleep_until(wake);
    }
  }

  void discard_input() override {
    check_up();
    std::lock_guard lock(bench_.mutex);
    emulator_.take_output(bench_.now());
    received_.clear();
  }

 private:
  void check_up() const {
    if (bench_.generation_ != generation_) throw LinkDown("test: the line went down");
  }

  Bench& bench_;
  C550Emulator& emulator_;
  const int generation_;
  std::deque<uint8_t> received_;
  std::string line_;
};

std::unique_ptr<ByteStream> Bench::open() {
  if (!available_) throw LinkDown("test: no device");
  std::lock_guard lock(mutex);
  pump_retired(now());
  emulators_.push_back(std::make_unique<C550Emulator>(controller_));
  return std::make_unique<EmulatedLine>(*this, *emulators_.back());
}

/// A tool-down move with yaw pi/2, which keeps joint 6 near +90 degrees.
Cmd move_to(int64_t sequence, double x, double y, double z) {
  Cmd c = test::tool_down_move(sequence, x, y, z, kPi / 2);
  c.source_utime = 1000 + sequence;
  return c;
}

Cmd gripper(int64_t sequence, int8_t action) {
  Cmd c{};
  c.sequence = sequence;
  c.mode = Cmd::MODE_GRIPPER_ONLY;
  c.gripper = action;
  c.speed = 0.5;
  c.sender = "test";
  return c;
}

/// The MA line the driver sends for `command` when the arm is at (or bound for) `reference`.
std::string ma_line(const Cmd& command, const Joints& reference) {
  CommandValidator validator(ArmGeometry::a465());
  const ValidationResult r = validator.validate(command, reference);
  if (!r.target) return "rejected: " + r.reason;
  rapl::JointArray q;
  for (int i = 0; i < 6; ++i) q[i] = r.target->joints[i];
  return rapl::move_joints(q);
}

std::string describe(const Status& s) {
  std::ostringstream out;
  out << "state " << int{s.state} << ", gripper " << int{s.gripper} << ", received "
      << s.last_received_sequence << ", executed " << s.last_executed_sequence << ", rejected "
      << s.last_rejected_sequence << " ('" << s.rejection_reason << "'), tool ("
      << s.tool_position[0] << ", " << s.tool_position[1] << ", " << s.tool_position[2]
      << "), error '" << s.error << "'";
  return out.str();
}

double distance(const Status& s, const Eigen::Vector3d& p) {
  return (Eigen::Vector3d(s.tool_position[0], s.tool_position[1], s.tool_position[2]) - p).norm();
}

/// A driver on a bench, its worker thread started; the worker stops before either goes.
class ArmDriverTest : public testing::Test {
 protected:
  void start(double delay = 0.05) {
    bench_ = std::make_unique<Bench>(quick(delay));
    DriverSettings settings;
    settings.idle_poll = 0.2;
    driver_ = std::make_unique<ArmDriver>(ArmGeometry::a465(), settings,
                                          [this] { return bench_->open(); });
    worker_ = std::jthread([this](std::stop_token stop) { driver_->run(stop); });
  }
  /// Sends a heartbeat from "test" every 0.2 s until the test ends, as a live commander does
  /// (the tests across an outage last longer than the commander timeout of 1.6 s).
  void keep_commanding() {
    heartbeat_ = std::jthread([this](std::stop_token stop) {
      Cmd beat{};
      beat.mode = Cmd::MODE_HEARTBEAT;
      beat.sender = "test";
      while (!stop.stop_requested()) {
        driver_->submit(beat);
        std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the heartbeat period
      }
    });
  }
  void TearDown() override {
    if (heartbeat_.joinable()) {
      heartbeat_.request_stop();
      heartbeat_.join();
    }
    if (worker_.joinable()) {
      worker_.request_stop();
      worker_.join();
    }
  }

  /// Waits up to kPatience for the status to satisfy `condition`.
  testing::AssertionResult eventually(const std::function<bool(const Status&)>& condition,
                                      const char* what) {
    if (sg::test::wait_until([&] { return condition(driver_->status().first); }, kPatience)) {
      return testing::AssertionSuccess();
    }
    return testing::AssertionFailure()
           << "no status with " << what << "; last: " << describe(driver_->status().first);
  }
  testing::AssertionResult connected() {
    return eventually([](const Status& s) { return s.state == Status::STATE_IDLE; }, "IDLE");
  }
  /// Waits until command `sequence` has been executed and the arm is at rest.
  testing::AssertionResult done(int64_t sequence) {
    return eventually(
        [&](const Status& s) {
          return s.last_executed_sequence == sequence && s.state == Status::STATE_IDLE;
        },
        "the command executed and the arm IDLE");
  }
  Status status() const { return driver_->status().first; }

  std::unique_ptr<Bench> bench_;
  std::unique_ptr<ArmDriver> driver_;
  std::jthread worker_;
  std::jthread heartbeat_;
};

const Joints kReady = C550Params{}.ready;

// A reachable Cartesian target is sent once (SPEED 50, then one MA with the validator's joints)
// and the status ends IDLE with the tool at the target and the command's sequence executed.
TEST_F(ArmDriverTest, ExecutesCartesianMove) {
  start();
  ASSERT_TRUE(connected());
  EXPECT_EQ(status().last_executed_sequence, -1);
  const Cmd command = move_to(1, 0.45, 0.0, 0.20);

  driver_->submit(command);

  ASSERT_TRUE(done(1));
  const Status s = status();
  EXPECT_LT(distance(s, {0.45, 0.0, 0.20}), 1e-3) << describe(s);
  EXPECT_LT((bench_->tool_position() - Eigen::Vector3d(0.45, 0.0, 0.20)).norm(), 1e-3);
  EXPECT_EQ(s.last_received_sequence, 1);
  EXPECT_EQ(s.last_rejected_sequence, -1);
  EXPECT_DOUBLE_EQ(s.speed, 0.5);
  EXPECT_EQ(s.source_utime, 0);  // idle again
  EXPECT_EQ(s.error, "");
  EXPECT_GT(s.interaction_time, 0.05);  // held for the interaction delay
  EXPECT_EQ(bench_->executed_starting("SPEED"), std::vector<std::string>{"SPEED 50"});
  EXPECT_EQ(bench_->executed_starting("MA "), std::vector<std::string>{ma_line(command, kReady)});
}

// A gripper-only CLOSE then OPEN each reach the controller once, the status reports CLOSED then
// OPEN, and the emulated fingers end closed (0 m) and open (0.08 m).
TEST_F(ArmDriverTest, GripperCloseOpenCycleShowsInStatus) {
  start();
  ASSERT_TRUE(connected());
  EXPECT_EQ(status().gripper, Status::GRIPPER_UNKNOWN);

  driver_->submit(gripper(1, Cmd::GRIPPER_CLOSE));
  ASSERT_TRUE(done(1));
  EXPECT_EQ(status().gripper, Status::GRIPPER_CLOSED);
  EXPECT_TRUE(eventually([&](const Status&) { return bench_->gripper_opening() == 0.0; },
                         "the fingers closed (0 m)"));

  driver_->submit(gripper(2, Cmd::GRIPPER_OPEN));
  ASSERT_TRUE(done(2));
  EXPECT_EQ(status().gripper, Status::GRIPPER_OPEN);
  EXPECT_TRUE(eventually([&](const Status&) { return bench_->gripper_opening() == 0.08; },
                         "the fingers open (0.08 m)"));

  EXPECT_EQ(bench_->executed_starting("CLOSE"), std::vector<std::string>{"CLOSE"});
  EXPECT_EQ(bench_->executed_starting("OPEN"), std::vector<std::string>{"OPEN"});
  EXPECT_TRUE(bench_->executed_starting("MA ").empty());
}

// STOP with GRIPPER_OPEN (the grasp machine's abort): ABORT, then OPEN; the hand opens.
TEST_F(ArmDriverTest, StopWithOpenAbortsThenOpensTheHand) {
  start();
  ASSERT_TRUE(connected());
  driver_->submit(gripper(1, Cmd::GRIPPER_CLOSE));
  ASSERT_TRUE(done(1));
  Cmd stop = gripper(2, Cmd::GRIPPER_OPEN);
  stop.mode = Cmd::MODE_STOP;
  driver_->submit(stop);
  ASSERT_TRUE(done(2));
  EXPECT_EQ(bench_->executed_starting("ABORT"), std::vector<std::string>{"ABORT"});
  EXPECT_EQ(bench_->executed_starting("OPEN"), std::vector<std::string>{"OPEN"});
  EXPECT_EQ(status().gripper, Status::GRIPPER_OPEN);
  EXPECT_TRUE(eventually([&](const Status&) { return bench_->gripper_opening() == 0.08; },
                         "the fingers open (0.08 m)"));
}

// A target inside the box but out of reach is rejected in the status with its reason, and no
// motion reaches the controller (a later gripper command shows the line kept working).
TEST_F(ArmDriverTest, RejectsUnreachableTargetWithoutSendingIt) {
  start();
  ASSERT_TRUE(connected());

  driver_->submit(move_to(1, 0.85, 0.0, 0.30));

  ASSERT_TRUE(eventually([](const Status& s) { return s.last_rejected_sequence == 1; },
                         "command 1 rejected"));
  const Status s = status();
  EXPECT_EQ(s.rejection_reason, "target (0.850, 0.000, 0.300) m: out of reach");
  EXPECT_EQ(s.last_received_sequence, 1);
  EXPECT_EQ(s.last_executed_sequence, -1);

  driver_->submit(gripper(2, Cmd::GRIPPER_CLOSE));
  ASSERT_TRUE(done(2));
  EXPECT_TRUE(bench_->executed_starting("MA ").empty());
  EXPECT_EQ(bench_->executed_starting("SPEED"), std::vector<std::string>{"SPEED 50"});
  EXPECT_LT((bench_->tool_position() - Eigen::Vector3d(0.33, 0.0, 0.409)).norm(), 1e-9);
}

// Latest wins: 100 moves submitted while the first move's interaction is held by the controller
// leave exactly two MA lines, the first command's and the newest's; none is sent twice, and the
// final executed sequence is the last one submitted.
TEST_F(ArmDriverTest, LatestWinsUnderBurstOfCommands) {
  start(/*delay=*/0.3);  // long enough to submit the burst while the first interaction is held
  ASSERT_TRUE(connected());
  const Cmd first = move_to(1, 0.40, 0.10, 0.25);
  driver_->submit(first);
  ASSERT_TRUE(eventually([&](const Status&) { return !bench_->executed_starting("MA ").empty(); },
                         "the first MA received by the controller"));

  Cmd last;
  for (int i = 1; i <= 100; ++i) {
    last = move_to(1 + i, 0.35 + 0.001 * i, -0.05, 0.20);
    driver_->submit(last);
  }
  ASSERT_EQ(status().last_executed_sequence, -1) << "the burst came after the first interaction";
  EXPECT_EQ(status().last_received_sequence, 101);

  ASSERT_TRUE(done(101));
  const std::vector<std::string> moves = bench_->executed_starting("MA ");
  EXPECT_EQ(moves, (std::vector<std::string>{ma_line(first, kReady), ma_line(last, kReady)}));
  EXPECT_EQ(std::set<std::string>(moves.begin(), moves.end()).size(), moves.size());
  EXPECT_LT(distance(status(), {0.45, -0.05, 0.20}), 1e-3);
  EXPECT_EQ(status().last_rejected_sequence, -1);
}

// The line goes down while idle: the status shows DISCONNECTED; a command submitted while the
// device is away is executed exactly once after the driver reconnects to a new session on the
// same controller.
TEST_F(ArmDriverTest, ReconnectsAfterLinkDownAndExecutesPendingCommandOnce) {
  start();
  ASSERT_TRUE(connected());
  keep_commanding();
  ASSERT_EQ(bench_->sessions(), 1);
  const Cmd command = move_to(1, 0.45, 0.0, 0.20);

  bench_->set_available(false);
  bench_->drop_line();
  ASSERT_TRUE(eventually([](const Status& s) { return s.state == Status::STATE_DISCONNECTED; },
                         "DISCONNECTED"));
  EXPECT_NE(status().error, "");
  driver_->submit(command);
  // A window, not a wait: the command is held through half a second of the outage.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(status().state, Status::STATE_DISCONNECTED);
  EXPECT_EQ(status().last_executed_sequence, -1);
  EXPECT_TRUE(bench_->executed_starting("MA ").empty());

  bench_->set_available(true);

  ASSERT_TRUE(done(1));
  EXPECT_EQ(bench_->sessions(), 2);
  EXPECT_EQ(bench_->executed_starting("MA "), std::vector<std::string>{ma_line(command, kReady)});
  EXPECT_LT(distance(status(), {0.45, 0.0, 0.20}), 1e-3);
  EXPECT_LT((bench_->tool_position() - Eigen::Vector3d(0.45, 0.0, 0.20)).norm(), 1e-3);
  EXPECT_EQ(status().error, "");
}

// The line goes down in the middle of an MA's echo (before its CR): nothing ran, so the driver
// sends the command again on the new session, and the controller executes it exactly once.
TEST_F(ArmDriverTest, ResendsCommandCutOffBeforeItsCarriageReturn) {
  start();
  ASSERT_TRUE(connected());
  keep_commanding();
  const Cmd command = move_to(1, 0.45, 0.0, 0.20);
  bench_->drop_when([](const std::string& line) { return line == "MA "; });

  driver_->submit(command);

  ASSERT_TRUE(done(1));
  EXPECT_EQ(bench_->sessions(), 2);
  EXPECT_EQ(bench_->executed_starting("MA "), std::vector<std::string>{ma_line(command, kReady)});
  EXPECT_LT((bench_->tool_position() - Eigen::Vector3d(0.45, 0.0, 0.20)).norm(), 1e-3);
}

// The line goes down after an MA's CR reached the controller: the move ran, so the driver does not
// send it again; after reconnecting the status counts it as executed and ends IDLE at its target.
TEST_F(ArmDriverTest, DoesNotResendCommandDeliveredBeforeLinkDown) {
  start();
  ASSERT_TRUE(connected());
  keep_commanding();
  driver_->submit(move_to(1, 0.40, 0.10, 0.25));
  ASSERT_TRUE(done(1));
  const Cmd command = move_to(2, 0.45, 0.0, 0.20);
  bench_->drop_when(
      [](const std::string& line) { return line.starts_with("MA ") && line.ends_with("\r"); });

  driver_->submit(command);

  ASSERT_TRUE(done(2));
  EXPECT_EQ(bench_->sessions(), 2);
  const std::vector<std::string> moves = bench_->executed_starting("MA ");
  ASSERT_EQ(moves.size(), 2u);
  EXPECT_EQ(moves[1], ma_line(command, kReady));
  EXPECT_LT(distance(status(), {0.45, 0.0, 0.20}), 1e-3);
}

// The line goes down right after a SPEED's CR, before the MA it prepares: the move never reached
// the controller, so it is sent again (with its SPEED) on the new session and executed once.
TEST_F(ArmDriverTest, ResendsMoveWhenLineDropsAfterItsSpeed) {
  start();
  ASSERT_TRUE(connected());
  keep_commanding();
  driver_->submit(move_to(1, 0.40, 0.10, 0.25));
  ASSERT_TRUE(done(1));
  Cmd command = move_to(2, 0.45, 0.0, 0.20);
  command.speed = 0.25;
  bench_->drop_when([](const std::string& line) { return line == "SPEED 25\r"; });

  driver_->submit(command);

  ASSERT_TRUE(done(2));
  EXPECT_EQ(bench_->sessions(), 2);
  EXPECT_EQ(bench_->executed_starting("SPEED"),
            (std::vector<std::string>{"SPEED 50", "SPEED 25", "SPEED 25"}));
  const std::vector<std::string> moves = bench_->executed_starting("MA ");
  ASSERT_EQ(moves.size(), 2u);
  EXPECT_EQ(moves[1], ma_line(command, kReady));
  EXPECT_DOUBLE_EQ(status().speed, 0.25);
  EXPECT_LT(distance(status(), {0.45, 0.0, 0.20}), 1e-3);
}

// A move with a CLOSE: the line goes down during the CLOSE's echo, after the MA ran. Only the
// CLOSE is sent again: each of MA and CLOSE reaches the controller exactly once.
TEST_F(ArmDriverTest, ResendsOnlyTheGripperWhenTheLineDropsAfterTheMove) {
  start();
  ASSERT_TRUE(connected());
  keep_commanding();
  Cmd command = move_to(1, 0.45, 0.0, 0.20);
  command.gripper = Cmd::GRIPPER_CLOSE;
  bench_->drop_when([](const std::string& line) { return line == "CL"; });

  driver_->submit(command);

  ASSERT_TRUE(done(1));
  EXPECT_EQ(bench_->sessions(), 2);
  EXPECT_EQ(bench_->executed_starting("MA ").size(), 1u);
  EXPECT_EQ(bench_->executed_starting("CLOSE"), std::vector<std::string>{"CLOSE"});
  EXPECT_EQ(status().gripper, stereograsp::arm_status_t::GRIPPER_CLOSED);
  EXPECT_LT(distance(status(), {0.45, 0.0, 0.20}), 1e-3);
}

// A gripper action gives way: a move with a CLOSE, and a newer move submitted while the first
// MA's interaction is held. The CLOSE is never sent: the first command counts as executed with
// the gripper as it was, the newer move follows, and the drop is counted.
TEST_F(ArmDriverTest, CloseGivesWayToANewerCommandWaiting) {
  start(/*delay=*/0.3);
  ASSERT_TRUE(connected());
  Cmd approach = move_to(1, 0.40, 0.10, 0.25);
  approach.gripper = Cmd::GRIPPER_CLOSE;
  driver_->submit(approach);
  ASSERT_TRUE(eventually([&](const Status&) { return !bench_->executed_starting("MA ").empty(); },
                         "the approach's MA received by the controller"));
  const Cmd replanned = move_to(2, 0.42, 0.05, 0.22);

  driver_->submit(replanned);

  ASSERT_TRUE(done(2));
  EXPECT_EQ(bench_->executed_starting("MA "),
            (std::vector<std::string>{ma_line(approach, kReady), ma_line(replanned, kReady)}));
  EXPECT_TRUE(bench_->executed_starting("CLOSE").empty());
  EXPECT_EQ(status().gripper, Status::GRIPPER_UNKNOWN);
  EXPECT_EQ(driver_->gripper_actions_dropped(), 1u);
  EXPECT_LT(distance(status(), {0.42, 0.05, 0.22}), 1e-3);
}

// A command arriving once the CLOSE is on the line waits for it: the hand closes, the newer move
// follows, and nothing counts as dropped.
TEST_F(ArmDriverTest, CloseAlreadySentIsNotUndone) {
  start(/*delay=*/0.3);
  ASSERT_TRUE(connected());
  Cmd approach = move_to(1, 0.40, 0.10, 0.25);
  approach.gripper = Cmd::GRIPPER_CLOSE;
  driver_->submit(approach);
  ASSERT_TRUE(eventually([&](const Status&) { return !bench_->executed_starting("CLOSE").empty(); },
                         "the approach's CLOSE received by the controller"));

  driver_->submit(move_to(2, 0.42, 0.05, 0.22));

  ASSERT_TRUE(done(2));
  EXPECT_EQ(bench_->executed_starting("CLOSE"), std::vector<std::string>{"CLOSE"});
  EXPECT_EQ(bench_->executed_starting("MA ").size(), 2u);
  EXPECT_EQ(status().gripper, Status::GRIPPER_CLOSED);
  EXPECT_EQ(driver_->gripper_actions_dropped(), 0u);
}

}  // namespace
}  // namespace sg::arm
