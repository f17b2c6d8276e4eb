#pragma once

#include <Eigen/Core>
#include <chrono>
#include <deque>
#include <fstream>
#include <memory>
#include <optional>

#include "common/bus.hpp"
#include "sim/ball_track.hpp"
#include "sim/c550_controller.hpp"
#include "sim/c550_emulator.hpp"
#include "sim/c550_sim_settings.hpp"
#include "sim/fault_injector.hpp"
#include "sim/pseudo_terminal.hpp"
#include "stereograsp/sim_arm_state_t.hpp"

namespace sg::sim {

/// The arm's true state at `t` (s since start) as SIM_ARM_STATE, stamped `utime`.
stereograsp::sim_arm_state_t arm_state_message(const C550Controller& c550, double t, int64_t utime);

/// sg-c550-sim's loop: the line (a pseudo-terminal that comes and goes, with its faults) and the
/// controller (which stays), SIM_ARM_STATE out and GROUND_TRUTH in (the ball a CLOSE grasps,
/// extrapolated from the last two frames to the moment it executes: BallTrack). Time is the steady
/// clock's since construction; run() returns when shutdown is requested.
class C550SimShell {
 public:
  /// `controller` and `bus` must outlive the shell. Throws when log_commands cannot be opened.
  C550SimShell(const C550SimSettings& settings, C550Controller& controller, Bus& bus);

  int run();

 private:
  double now() const;
  void connect();
  void schedule_line(double t);  ///< drops the line at disconnect_after, brings one back later
  double next_event() const;
  void wait(double seconds);
  void serve(double t);
  void receive(double t);
  void transmit();
  void log_commands(double t);

  const C550SimSettings& s_;
  C550Controller& controller_;
  Bus& bus_;
  Symlink link_;
  FaultInjector faults_;
  std::ofstream log_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::unique_ptr<PseudoTerminal> pty_;
  std::unique_ptr<C550Emulator> emulator_;
  std::deque<uint8_t> tx_;
  BallTrack ball_;  ///< GROUND_TRUTH, extrapolated to the moment a CLOSE executes
  size_t logged_ = 0;
  bool disconnected_ = false;
  double reconnect_at_ = 0;
};

}  // namespace sg::sim
