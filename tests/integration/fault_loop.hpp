#pragma once

// The closed loop in simulation for fault injection (issue 15): real processes over real LCM and
// a real pseudo-terminal, each startable, killable (SIGKILL) and restartable on its own, and an
// observer that keeps what a fault run is judged by: every ARM_COMMAND seen, the driver's
// executed sequences per driver instance, the simulator's true joints over time, and the
// RAPL-II command log of sg-c550-sim (--log-commands).
//
//     FaultLoop loop(7941, files);          // files: calibration and coefficients, made once
//     loop.start_all();                     // c550, driver, vision, predictor, grasp, cameras
//     loop.grasp_ctl({"track"});
//     ASSERT_TRUE(loop.eventually([&] { return loop.seen().at_standoff(0.10); }, 60s, "..."));
//     loop.kill("grasp");
//     CommandAudit audit = audit_commands(loop.command_log());

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "arm_driver/kinematics.hpp"
#include "common/bus.hpp"
#include "common/message_types.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::test {

/// The files every run shares: made once by sg-predictor train and sg-camera-sim.
struct LoopFiles {
  std::string dir;
  std::string calibration;   ///< sg-camera-sim --calibration-out
  std::string coefficients;  ///< sg-predictor train on the paper's circle
  /// Makes them in a new temporary directory (gtest assertions on failure).
  static LoopFiles make();
};

/// One ARM_COMMAND as the test received it.
struct CommandSeen {
  int64_t recv_utime = 0;
  std::string sender;
  int8_t mode = 0;
  int64_t sequence = 0;
};

/// The simulator's truth at a moment.
struct SimSample {
  int64_t recv_utime = 0;  ///< SIM_ARM_STATE.utime: the simulator's clock (this host's)
  arm::Joints joints = arm::Joints::Zero();
  bool holding = false;
};

/// What the test hears on the loop's bus.
class LoopObserver {
 public:
  explicit LoopObserver(Bus& bus);

  /// The newest forecast tracks the ball, from a frame captured after `utime`.
  bool tracking_since(int64_t utime) const;
  /// The tool centre point within 3 cm of the point `standoff` above the true ball.
  bool at_standoff(double standoff) const;
  /// Receive time of the last ARM_COMMAND whose sender starts with `prefix`, at or before
  /// `before` (0 when none).
  int64_t last_command_from(const std::string& prefix, int64_t before) const;
  /// ARM_COMMAND received in [from, to] from senders starting with `prefix`; `motion`: only
  /// those that are not MODE_HEARTBEAT / MODE_RELEASE.
  int count_commands(const std::string& prefix, int64_t from, int64_t to, bool motion) const;
  /// The first moment after `after` from which the true joints never changed again (by more
  /// than 1e-6 rad) up to the newest sample, provided that stretch lasts `settled` s; nullopt
  /// when the arm still moves.
  std::optional<int64_t> at_rest_since(int64_t after, double settled = 1.0) const;
  /// Sequences reported executed by more than one driver instance (driver_start_utime).
  std::vector<int64_t> executed_by_two_drivers() const;

  const stereograsp::arm_status_t& arm() const { return arm_; }
  int arm_statuses() const { return arm_statuses_; }
  const std::optional<stereograsp::grasp_status_t>& grasp() const { return grasp_; }
  const std::vector<CommandSeen>& commands() const { return commands_; }
  const std::vector<SimSample>& sim() const { return sim_; }
  const stereograsp::point3_t& ball() const { return ball_; }

 private:
  stereograsp::arm_status_t arm_{};
  int arm_statuses_ = 0;
  std::map<int64_t, std::map<int64_t, int>> executed_;  ///< sequence -> driver start -> 1
  std::optional<stereograsp::grasp_status_t> grasp_;
  std::vector<CommandSeen> commands_;
  std::vector<SimSample> sim_;
  stereograsp::trajectory_t forecast_{};
  stereograsp::point3_t ball_{};
};

/// What the simulated controller was told, from its --log-commands file.
struct CommandAudit {
  int motions = 0;              ///< MA lines (every motion the driver sent)
  int repeated_motions = 0;     ///< MA lines identical to an earlier one (a motion sent twice)
  int outside_limits = 0;       ///< MA targets outside the joint limits or the workspace box
  std::vector<int64_t> aborts;  ///< utime of each ABORT
  std::vector<int64_t> opens;   ///< utime of each OPEN
  std::vector<int64_t> acts;    ///< utime of each command that acts (MA, READY, OPEN, CLOSE, ...)
};

/// Reads sg-c550-sim's command log ("utime<TAB>seconds<TAB>command" lines) and judges it with the
/// product's arm geometry (ArmGeometry::a465(), joint limits and workspace box).
CommandAudit audit_commands(const std::string& log_path);

/// The loop's processes by name: "c550", "driver", "vision", "predictor", "grasp", "cameras".
class FaultLoop {
 public:
  struct Options {
    std::vector<std::string> c550_args;    ///< extra sg-c550-sim flags (line faults)
    std::vector<std::string> grasp_prefix; ///< run sg-grasp under this (e.g. faketime -f +1s)
    std::vector<std::string> grasp_args;   ///< extra sg-grasp flags (e.g. --speed 0.1)
  };

  FaultLoop(int port, LoopFiles files, Options options);
  FaultLoop(int port, LoopFiles files) : FaultLoop(port, std::move(files), Options{}) {}
  ~FaultLoop();

  /// Starts every process in order and waits until the arm is at rest and the ball forecast.
  void start_all();
  /// Starts (or restarts) one process; waits until it has joined the bus.
  void start(const std::string& name);
  /// SIGKILL, then reaps it; returns the time of the kill.
  int64_t kill(const std::string& name);
  /// Runs sg-grasp-ctl with `args` (and the loop's URL), watching the bus meanwhile.
  ProcessResult grasp_ctl(const std::vector<std::string>& args,
                          std::chrono::milliseconds timeout = std::chrono::seconds(60));
  /// Runs sg-arm-ctl with `args`.
  ProcessResult arm_ctl(const std::vector<std::string>& args,
                        std::chrono::milliseconds timeout = std::chrono::seconds(60));
  /// The tracking command, repeated (as an operator would) until sg-grasp accepts it.
  bool track();

  /// eventually() on the loop's bus.
  ::testing::AssertionResult eventually(const std::function<bool()>& condition,
                                        std::chrono::milliseconds deadline,
                                        const std::string& what);
  /// Handles the bus for `duration`.
  void watch_for(std::chrono::milliseconds duration);

  Bus& bus() { return *bus_; }
  const LoopObserver& seen() const { return *seen_; }
  std::string url() const { return url_; }
  std::string command_log() const { return dir_ + "/c550-commands.tsv"; }
  /// stderr of every process so far (for failure messages).
  std::string logs();
  pid_t pid(const std::string& name) const;

 private:
  std::vector<std::string> argv(const std::string& name) const;
  /// Runs `argv` to its end (or `timeout`) while the observer keeps handling the bus.
  ProcessResult run_watching(const std::vector<std::string>& argv,
                             std::chrono::milliseconds timeout);

  int port_;
  LoopFiles files_;
  Options options_;
  std::string url_;
  std::string dir_;
  std::unique_ptr<Bus> bus_;
  std::unique_ptr<LoopObserver> seen_;
  std::map<std::string, std::unique_ptr<Child>> children_;
  std::string finished_logs_;
};

}  // namespace sg::test
