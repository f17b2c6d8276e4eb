#pragma once

/// The bench tools' side of the commander lease (docs/arm.md, "One commander and the watchdog"):
/// sends a signed ARM_COMMAND, keeps the lease alive with MODE_HEARTBEAT every 0.2 s (the same
/// sequence: a heartbeat consumes none) while ARM_STATUS shows the command under way, and gives
/// the lease back with MODE_RELEASE. sg-arm-driver's watchdog stops the arm when these
/// heartbeats stop, so a bench tool that dies mid-move leaves the arm standing, not running.
///
///     sg::arm::ArmCommander commander(bus, lab);           // lab signs as sg-arm-ctl@host:pid
///     const CommandReport r = commander.execute(command, 10.0);   // sg-arm-ctl: blocks
///     if (r.result != CommandReport::kExecuted) std::puts(r.reason.c_str());
///
///     commander.send(command);      // sg-calibrate robot: step by step, from its own loop
///     commander.tick();             // every pass of the loop: a heartbeat when one is due
///     commander.release();          // at the end (the destructor does it too)

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"

namespace sg::arm {

/// How a command sent with ArmCommander::execute() ended.
struct CommandReport {
  enum Result {
    kExecuted,     ///< executed and the arm at rest (a STOP: executed)
    kRejected,     ///< rejected by the driver, or refused by the lease (reason from ARM_STATUS)
    kTakenOver,    ///< another sender took the lease before the arm came to rest
    kInterrupted,  ///< Ctrl-C (sg::shutdown_requested): a STOP was sent
    kTimedOut,     ///< not reported executed and at rest within the time allowed
  };
  Result result = kTimedOut;
  std::string reason;  ///< every result but kExecuted: why, one line
};

class ArmCommander {
 public:
  /// Subscribes to ARM_STATUS on `bus`; commands are signed by `signer` (its instance name is
  /// the lease holder's name). `heartbeat_period` in seconds, well below the driver's
  /// commander_timeout (1.6 s by default).
  ArmCommander(Bus& bus, auth::LabAccess& signer, double heartbeat_period = 0.2);
  /// Releases a lease still held.
  ~ArmCommander();
  ArmCommander(const ArmCommander&) = delete;
  ArmCommander& operator=(const ArmCommander&) = delete;

  /// Signs and publishes `command`; from now on tick() keeps the lease alive (MODE_STOP aside:
  /// it needs no lease).
  void send(stereograsp::arm_cmd_t command);
  /// Sends a heartbeat if one is due (a command was sent and the lease not released).
  void tick();
  /// Sends MODE_STOP (obeyed from anyone) with the next sequence.
  void stop();
  /// Sends MODE_RELEASE if a command was sent and not released yet; heartbeats end.
  void release();

  /// send(), then handles the bus (sending heartbeats) until ARM_STATUS reports `command`
  /// executed and the arm at rest, or rejected; then release(). On Ctrl-C before that: stop(),
  /// release(). `timeout`: seconds.
  CommandReport execute(stereograsp::arm_cmd_t command, double timeout);

  /// Whether any ARM_STATUS has arrived, and the newest.
  bool have_status() const { return state_->statuses > 0; }
  const stereograsp::arm_status_t& status() const { return state_->status; }
  /// The sender name the commands carry ("" before the first).
  const std::string& name() const { return name_; }

 private:
  /// What the ARM_STATUS handler writes: shared with it, so that the bus may outlive this.
  struct State {
    stereograsp::arm_status_t status{};
    uint64_t statuses = 0;
  };
  void publish(stereograsp::arm_cmd_t command);
  stereograsp::arm_cmd_t bare(int8_t mode, int64_t sequence) const;
  /// The report once `sequence` is done, rejected or taken over; kTimedOut while under way.
  CommandReport judge(int64_t sequence, bool needs_rest) const;

  Bus& bus_;
  auth::LabAccess& signer_;
  std::chrono::duration<double> period_;
  std::shared_ptr<State> state_ = std::make_shared<State>();
  std::string name_;
  int64_t sequence_ = 0;  ///< of the last command sent: heartbeats repeat it
  bool holding_ = false;  ///< a command that needs the lease was sent and not released
  std::chrono::steady_clock::time_point last_sent_{};
};

}  // namespace sg::arm
