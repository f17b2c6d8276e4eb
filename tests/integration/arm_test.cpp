// sg-arm-driver and sg-c550-sim as processes on a real pseudo-terminal, over real LCM: a move, a
// gripper cycle, a rejected target, latest-wins under a burst, recovery after a disconnect,
// sg-arm-ctl at the bench, the commander lease (sg-arm-ctl refused while another sender holds it,
// obeyed with --take-over) and the watchdog (a silent commander's long move gets ABORT). The
// test's commands are signed with the lab key in $SG_LAB_KEY (ctest gives it;
// docs/security.md); while the rig waits it sends a heartbeat every 0.2 s, as a live commander
// does, unless told to fall silent.

#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <thread>

#include "auth/command_auth.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/arm_commands.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
using stereograsp::arm_cmd_t;
using stereograsp::arm_status_t;
using stereograsp::sim_arm_state_t;
constexpr double kPi = 3.14159265358979323846;

/// The RAPL-II lines sg-c550-sim logged (--log-commands): the third tab-separated field.
std::vector<std::string> logged_commands(const std::string& path) {
  std::vector<std::string> lines;
  std::istringstream in(read_text(path));
  for (std::string line; std::getline(in, line);) {
    const auto second_tab = line.find('\t', line.find('\t') + 1);
    if (second_tab != std::string::npos) lines.push_back(line.substr(second_tab + 1));
  }
  return lines;
}

/// Lines starting with `prefix`.
std::vector<std::string> starting_with(const std::vector<std::string>& lines,
                                       const std::string& prefix) {
  std::vector<std::string> out;
  for (const auto& l : lines) {
    if (l.rfind(prefix, 0) == 0) out.push_back(l);
  }
  return out;
}

/// The first repeated line, or "" when every line is distinct.
std::string first_repeat(const std::vector<std::string>& lines) {
  std::map<std::string, int> seen;
  for (const auto& l : lines) {
    if (++seen[l] == 2) return l;
  }
  return "";
}

/// A tool-down Cartesian move; yaw = azimuth + pi keeps joint 6 away from its +-180 deg limit.
arm_cmd_t move_to(int64_t sequence, double x, double y, double z) {
  arm_cmd_t c = tool_down_move(sequence, x, y, z, std::atan2(y, x) + kPi);
  c.utime = now_utime();
  c.sender = "arm_test";
  return c;
}

arm_cmd_t gripper(int64_t sequence, int8_t action) {
  arm_cmd_t c{};
  c.utime = now_utime();
  c.sequence = sequence;
  c.mode = arm_cmd_t::MODE_GRIPPER_ONLY;
  c.gripper = action;
  c.speed = 0.5;
  c.sender = "arm_test";
  return c;
}

/// sg-c550-sim on a pseudo-terminal (linked at dir/c550), sg-arm-driver on it, and a bus that
/// keeps the newest ARM_STATUS and SIM_ARM_STATE.
class ArmRig {
 public:
  ArmRig(int port, std::vector<std::string> sim_flags)
      : dir_(make_temp_dir()), url_(test_url(port)), bus_(url_) {
    bus_.set_guard(vouching_as("sg-arm-ctl"));  // the driver believes commands only from commanders
    bus_.subscribe<arm_status_t>("ARM_STATUS", [this](const arm_status_t& s, const ReceiveInfo&) {
      status_ = s;
      ++status_count_;
      if (s.state == arm_status_t::STATE_DISCONNECTED) saw_disconnected_ = true;
    });
    bus_.subscribe<sim_arm_state_t>(
        "SIM_ARM_STATE", [this](const sim_arm_state_t& s, const ReceiveInfo&) { truth_ = s; });
    std::vector<std::string> sim = {program("sg-c550-sim"),
                                    "--lcm-url",
                                    url_,
                                    "--link",
                                    device(),
                                    "--log-commands",
                                    command_log(),
                                    "--delay-min",
                                    "0.3",
                                    "--delay-max",
                                    "0.4",
                                    "--speed",
                                    "100"};
    sim.insert(sim.end(), sim_flags.begin(), sim_flags.end());
    sim_ = std::make_unique<Child>(sim);
    EXPECT_TRUE(eventually([&] { return std::filesystem::exists(device()); }, 30s,
                           "sg-c550-sim's pseudo-terminal at " + device()));
    driver_ = std::make_unique<Child>(std::vector<std::string>{
        program("sg-arm-driver"), "--lcm-url", url_, "--device", device()});
  }

  ~ArmRig() {
    driver_->signal(SIGINT);
    sim_->signal(SIGINT);
    driver_->wait(5s);
    sim_->wait(5s);
  }

  std::string device() const { return dir_ + "/c550"; }
  std::string command_log() const { return dir_ + "/commands.log"; }
  const std::string& url() const { return url_; }
  Bus& bus() { return bus_; }
  /// Signs `c` with the lab key ($SG_LAB_KEY, as the driver reads it) and publishes it.
  void command(arm_cmd_t c) {
    if (c.mode != arm_cmd_t::MODE_HEARTBEAT) last_sequence_ = c.sequence;
    signer_.sign("ARM_COMMAND", c);
    bus_.publish("ARM_COMMAND", c);
    last_sent_ = std::chrono::steady_clock::now();
  }
  /// From now on wait_until() sends no heartbeats: the commander has gone silent.
  void fall_silent() { silent_ = true; }
  const arm_status_t& status() const { return status_; }
  const sim_arm_state_t& truth() const { return truth_; }
  bool saw_disconnected() const { return saw_disconnected_; }

  /// Handles messages until `done()` holds or `timeout` passes, with a heartbeat every 0.2 s
  /// after the first command (unless silent); returns done().
  bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!done() && std::chrono::steady_clock::now() < deadline) {
      bus_.handle(20ms);
      if (!silent_ && last_sequence_ >= 0 && std::chrono::steady_clock::now() - last_sent_ >= 200ms)
        command(heartbeat(last_sequence_));
    }
    return done();
  }
  /// A heartbeat carrying the sender's last sequence.
  static arm_cmd_t heartbeat(int64_t sequence) {
    arm_cmd_t c{};
    c.utime = now_utime();
    c.sequence = sequence;
    c.mode = arm_cmd_t::MODE_HEARTBEAT;
    return c;
  }

  /// Waits for the driver's first status with the controller connected.
  bool wait_connected() {
    return wait_until(
        [&] { return status_count_ > 0 && status_.state != arm_status_t::STATE_DISCONNECTED; },
        20s);
  }

  /// Waits until `sequence` is executed and the arm is at rest.
  bool wait_executed(int64_t sequence, std::chrono::seconds timeout = 20s) {
    return wait_until(
        [&] {
          return status_.last_executed_sequence == sequence &&
                 status_.state == arm_status_t::STATE_IDLE;
        },
        timeout);
  }

 private:
  std::string dir_;
  std::string url_;
  Bus bus_;
  auth::CommandSigner signer_{auth::command_key(auth::LabKey::load(auth::default_key_path())),
                              "arm_test"};
  std::unique_ptr<Child> sim_;
  std::unique_ptr<Child> driver_;
  arm_status_t status_{};
  sim_arm_state_t truth_{};
  int status_count_ = 0;
  bool saw_disconnected_ = false;
  int64_t last_sequence_ = -1;  ///< of the last command: heartbeats repeat it
  std::chrono::steady_clock::time_point last_sent_{};
  bool silent_ = false;
};

/// Distance from the status's tool centre point to (x, y, z).
double tool_error(const arm_status_t& s, double x, double y, double z) {
  return std::hypot(s.tool_position[0] - x, s.tool_position[1] - y, s.tool_position[2] - z);
}

// A Cartesian move reaches the target: ARM_STATUS and the simulator's true state agree within 1 mm.
TEST(ArmProcesses, MoveGripperCycleAndRejection) {
  ASSERT_TRUE(multicast_available(7916));
  ArmRig rig(7916, {});
  ASSERT_TRUE(rig.wait_connected());
  rig.command(move_to(1, 0.45, 0.10, 0.30));
  ASSERT_TRUE(rig.wait_executed(1)) << rig.status().error << rig.status().rejection_reason;
  EXPECT_LT(tool_error(rig.status(), 0.45, 0.10, 0.30), 1e-3);
  ASSERT_TRUE(rig.wait_until(
      [&] {
        const auto& t = rig.truth();
        return std::hypot(t.tool_position[0] - 0.45, t.tool_position[1] - 0.10,
                          t.tool_position[2] - 0.30) < 1e-3;
      },
      10s));
  EXPECT_GT(rig.status().interaction_time, 0.3);

  // Gripper: close, then open; the status and the simulator's finger opening follow.
  rig.command(gripper(2, arm_cmd_t::GRIPPER_CLOSE));
  ASSERT_TRUE(rig.wait_executed(2));
  EXPECT_TRUE(
      rig.wait_until([&] { return rig.status().gripper == arm_status_t::GRIPPER_CLOSED; }, 5s));
  EXPECT_TRUE(rig.wait_until([&] { return rig.truth().gripper_opening < 1e-3; }, 5s));
  rig.command(gripper(3, arm_cmd_t::GRIPPER_OPEN));
  ASSERT_TRUE(rig.wait_executed(3));
  EXPECT_TRUE(
      rig.wait_until([&] { return rig.status().gripper == arm_status_t::GRIPPER_OPEN; }, 5s));
  EXPECT_TRUE(rig.wait_until([&] { return rig.truth().gripper_opening > 0.079; }, 5s));

  // Out of reach inside the workspace box: rejected with a reason, nothing reaches the controller.
  const size_t before = starting_with(logged_commands(rig.command_log()), "MA").size();
  rig.command(move_to(4, 0.85, 0.85, 1.20));
  ASSERT_TRUE(rig.wait_until([&] { return rig.status().last_rejected_sequence == 4; }, 10s));
  EXPECT_FALSE(rig.status().rejection_reason.empty());
  EXPECT_EQ(rig.status().last_executed_sequence, 3);
  // A stale sequence number is refused too.
  rig.command(move_to(2, 0.40, 0.0, 0.40));
  ASSERT_TRUE(rig.wait_until([&] { return rig.status().last_rejected_sequence == 2; }, 10s));
  // A window, not a wait: no MA may reach the controller in the second after the refusals.
  std::this_thread::sleep_for(1s);
  EXPECT_EQ(starting_with(logged_commands(rig.command_log()), "MA").size(), before);
}

/// Closes the gripper (command `sequence`) while `truth` publishes the ball at the tool,
/// (0.45, 0.10, 0.30), at 20 Hz; whether sg-c550-sim then says it holds the ball.
bool close_on_a_ball_from(ArmRig& rig, Bus& truth, int64_t sequence) {
  stereograsp::point3_t ball{};
  ball.visible = 1;
  ball.position[0] = 0.45, ball.position[1] = 0.10, ball.position[2] = 0.30;
  const auto publish = [&] {
    ball.utime = now_utime();
    truth.publish("GROUND_TRUTH", ball);
  };
  for (int i = 0; i < 10; ++i) {  // half a second of the ball there before the close
    publish();
    rig.wait_until([] { return false; }, 50ms);
  }
  rig.command(gripper(sequence, arm_cmd_t::GRIPPER_CLOSE));
  for (int i = 0; i < 200 && rig.status().last_executed_sequence != sequence; ++i) {
    publish();
    rig.wait_until([&] { return rig.status().last_executed_sequence == sequence; }, 50ms);
  }
  rig.wait_until([] { return false; }, 300ms);  // a SIM_ARM_STATE sent since
  return rig.truth().holding_object != 0;
}

// GROUND_TRUTH is believed only from sg-camera-sim: a ball published at the open gripper by a
// host without credentials, or vouched for as sg-vision, is not grasped by the close; the same
// ball vouched for as sg-camera-sim is.
TEST(ArmProcesses, OnlyTheCamerasTruthPutsABallInTheGripper) {
  ASSERT_TRUE(multicast_available(7919));
  ArmRig rig(7919, {});
  ASSERT_TRUE(rig.wait_connected());
  rig.command(move_to(1, 0.45, 0.10, 0.30));
  ASSERT_TRUE(rig.wait_executed(1)) << rig.status().error << rig.status().rejection_reason;
  Bus stranger(rig.url()), vision(rig.url()), cameras(rig.url());
  vision.set_guard(vouching_as("sg-vision"));
  cameras.set_guard(vouching_as("sg-camera-sim"));
  EXPECT_FALSE(close_on_a_ball_from(rig, stranger, 2)) << "an unvouched ball was grasped";
  rig.command(gripper(3, arm_cmd_t::GRIPPER_OPEN));
  ASSERT_TRUE(rig.wait_executed(3));
  EXPECT_FALSE(close_on_a_ball_from(rig, vision, 4)) << "sg-vision's ball was grasped";
  rig.command(gripper(5, arm_cmd_t::GRIPPER_OPEN));
  ASSERT_TRUE(rig.wait_executed(5));
  EXPECT_TRUE(close_on_a_ball_from(rig, cameras, 6)) << "the cameras' ball was not grasped";
}

// A burst of 100 commands while one interaction is in flight: the newest wins, no backlog, and no
// command reaches the controller twice.
TEST(ArmProcesses, LatestWinsUnderABurst) {
  ASSERT_TRUE(multicast_available(7917));
  ArmRig rig(7917, {});
  ASSERT_TRUE(rig.wait_connected());
  for (int i = 1; i <= 100; ++i) {
    const double a = 0.01 * i;
    rig.command(move_to(i, 0.50 * std::cos(a), 0.50 * std::sin(a), 0.30));
    std::this_thread::sleep_for(2ms);  // pacing: the burst (100 in 0.2 s) is what is under test
  }
  ASSERT_TRUE(rig.wait_executed(100, 30s)) << rig.status().error;
  EXPECT_LT(tool_error(rig.status(), 0.50 * std::cos(1.0), 0.50 * std::sin(1.0), 0.30), 1e-3);
  const auto moves = starting_with(logged_commands(rig.command_log()), "MA");
  EXPECT_GE(moves.size(), 1u);
  EXPECT_LE(moves.size(), 4u) << "a backlog: " << moves.size() << " moves for a 0.2 s burst";
  EXPECT_EQ(first_repeat(moves), "");
}

// The line goes away for a second mid-session: the driver reports DISCONNECTED, reconnects, and
// every command is executed at most once, with the newest executed in the end.
TEST(ArmProcesses, RecoversAfterADisconnect) {
  ASSERT_TRUE(multicast_available(7918));
  ArmRig rig(7918, {"--disconnect-after", "3", "--reconnect-after", "1"});
  ASSERT_TRUE(rig.wait_connected());
  int64_t sequence = 0;
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < 7s) {
    ++sequence;
    const double a = 0.2 * static_cast<double>(sequence);
    rig.command(move_to(sequence, 0.50 * std::cos(a), 0.50 * std::sin(a), 0.35));
    rig.wait_until([] { return false; }, 1s);  // pacing: one a second, across the line's outage
  }
  ASSERT_TRUE(rig.wait_executed(sequence, 30s)) << rig.status().error;
  EXPECT_TRUE(rig.saw_disconnected());
  const double a = 0.2 * static_cast<double>(sequence);
  EXPECT_LT(tool_error(rig.status(), 0.50 * std::cos(a), 0.50 * std::sin(a), 0.35), 1e-3);
  const auto commands = logged_commands(rig.command_log());
  EXPECT_GE(starting_with(commands, "NOH").size(), 2u) << "no second session after the disconnect";
  EXPECT_EQ(first_repeat(starting_with(commands, "MA")), "");
}

// sg-arm-ctl at the bench: `move X Y Z --wait` returns once the arm is there; `status` prints it.
TEST(ArmProcesses, ArmCtlMovesTheArm) {
  ASSERT_TRUE(multicast_available(7919));
  ArmRig rig(7919, {});
  ASSERT_TRUE(rig.wait_connected());
  const ProcessResult moved = run(
      {program("sg-arm-ctl"), "--lcm-url", rig.url(), "move", "0.5", "0.1", "0.3", "--wait"}, 30s);
  EXPECT_EQ(moved.exit_code, 0) << moved.out << moved.err;
  EXPECT_NE(moved.out.find("executed"), std::string::npos) << moved.out;
  ASSERT_TRUE(rig.wait_until([&] { return tool_error(rig.status(), 0.5, 0.1, 0.3) < 1e-3; }, 10s));
  const ProcessResult shown = run({program("sg-arm-ctl"), "--lcm-url", rig.url(), "status"}, 10s);
  EXPECT_EQ(shown.exit_code, 0) << shown.err;
  EXPECT_NE(shown.out.find("(0.5000, 0.1000, 0.3000)"), std::string::npos) << shown.out;
  const ProcessResult refused =
      run({program("sg-arm-ctl"), "--lcm-url", rig.url(), "move", "3", "0", "0.3"}, 30s);
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE((refused.out + refused.err).find("rejected"), std::string::npos)
      << refused.out << refused.err;
}

/// Another commander: from its own thread and bus, a move and then a heartbeat every 0.2 s,
/// signed as `name`, until it goes.
class OtherCommander {
 public:
  OtherCommander(const std::string& url, const std::string& name)
      : thread_([url, name](std::stop_token stop) {
          Bus bus(url);
          bus.set_guard(vouching_as("sg-arm-ctl"));
          auth::CommandSigner signer(
              auth::command_key(auth::LabKey::load(auth::default_key_path())), name);
          arm_cmd_t c = move_to(1, 0.40, 0.0, 0.35);
          while (!stop.stop_requested()) {
            signer.sign("ARM_COMMAND", c);
            bus.publish("ARM_COMMAND", c);
            std::this_thread::sleep_for(200ms);  // the heartbeat period
            c = ArmRig::heartbeat(1);
          }
        }) {}

 private:
  std::jthread thread_;
};

// While another sender holds the lease, `sg-arm-ctl move` is refused with the holder named and
// exits 1, the arm unmoved; with --take-over it is obeyed, and the arm arrives.
TEST(ArmProcesses, ArmCtlHonoursTheLeaseAndTakesItOver) {
  ASSERT_TRUE(multicast_available(7927));
  ArmRig rig(7927, {});
  ASSERT_TRUE(rig.wait_connected());
  OtherCommander holder(rig.url(), "holder@bench:1");
  ASSERT_TRUE(rig.wait_until([&] { return rig.status().commander == "holder@bench:1"; }, 10s))
      << "commander '" << rig.status().commander << "'";
  ASSERT_TRUE(rig.wait_until([&] { return rig.status().state == arm_status_t::STATE_IDLE; }, 10s));

  const ProcessResult refused =
      run({program("sg-arm-ctl"), "--lcm-url", rig.url(), "move", "0.5", "0.1", "0.3"}, 30s);
  EXPECT_EQ(refused.exit_code, 1) << refused.out << refused.err;
  EXPECT_NE(refused.out.find("rejected: arm commanded by 'holder@bench:1' (heard "),
            std::string::npos)
      << refused.out << refused.err;
  EXPECT_NE(refused.out.find("sg-arm-ctl --take-over takes it"), std::string::npos) << refused.out;
  EXPECT_EQ(rig.status().commander, "holder@bench:1");
  EXPECT_GT(tool_error(rig.status(), 0.5, 0.1, 0.3), 0.05);  // not moved there

  const ProcessResult taken = run(
      {program("sg-arm-ctl"), "--lcm-url", rig.url(), "--take-over", "move", "0.5", "0.1", "0.3"},
      30s);
  EXPECT_EQ(taken.exit_code, 0) << taken.out << taken.err;
  EXPECT_NE(taken.out.find("executed"), std::string::npos) << taken.out;
  EXPECT_TRUE(rig.wait_until([&] { return tool_error(rig.status(), 0.5, 0.1, 0.3) < 1e-3; }, 10s));
}

// The watchdog: a signed long, slow move, then silence. The emulator logs ABORT no sooner than
// the commander timeout (1.6 s) after the command and no later than the timeout plus one
// interaction (sg-c550-sim here: at most 0.4 s), with 0.3 s allowed for delivery and scheduling
// on a loaded machine; the gripper is not touched, the arm stops short of the target, and
// ARM_STATUS says why.
TEST(ArmProcesses, WatchdogAbortsASilentCommandersMove) {
  ASSERT_TRUE(multicast_available(7928));
  ArmRig rig(7928, {});
  ASSERT_TRUE(rig.wait_connected());
  rig.fall_silent();
  arm_cmd_t slow = move_to(1, 0.40, -0.30, 0.20);
  slow.speed = 0.03;
  const int64_t sent = now_utime();
  rig.command(slow);
  ASSERT_TRUE(rig.wait_until([&] { return !rig.status().watchdog.empty(); }, 10s))
      << rig.status().error;
  EXPECT_EQ(rig.status().watchdog.rfind("stopped: 'arm_test' silent for 1.", 0), 0u)
      << rig.status().watchdog;
  EXPECT_EQ(rig.status().commander, "");
  ASSERT_TRUE(rig.wait_until(
      [&] { return !starting_with(logged_commands(rig.command_log()), "ABORT").empty(); }, 5s));
  int64_t abort_utime = 0;
  std::istringstream log(read_text(rig.command_log()));
  for (std::string line; std::getline(log, line);) {
    if (line.find("\tABORT") != std::string::npos) abort_utime = std::stoll(line);
  }
  const double after = static_cast<double>(abort_utime - sent) * 1e-6;
  std::printf("ABORT logged %.2f s after the command\n", after);
  EXPECT_GE(after, 1.6);
  EXPECT_LE(after, 1.6 + 0.4 + 0.3);
  const auto commands = logged_commands(rig.command_log());
  EXPECT_EQ(starting_with(commands, "ABORT").size(), 1u);
  EXPECT_TRUE(starting_with(commands, "OPEN").empty());
  EXPECT_TRUE(starting_with(commands, "CLOSE").empty());
  ASSERT_TRUE(rig.wait_until([&] { return rig.status().state == arm_status_t::STATE_IDLE; }, 5s));
  EXPECT_GT(tool_error(rig.status(), 0.40, -0.30, 0.20), 0.02) << "stopped short of the target";
  EXPECT_EQ(rig.status().last_executed_sequence, 1);
}

}  // namespace
}  // namespace sg::test
