#pragma once

/// One commander at a time (issue 15, DESIGN.md rule 5): the lease that sg-arm-driver grants to
/// the sender of ARM_COMMAND, "<program>@<host>:<pid>" (sg::instance_name), whose commands it
/// obeys. A pure state machine: no clock; every call takes the time `t` in seconds of the
/// driver's clock.
///
/// Lifecycle, for a command from sender S at time t (h = the holder, t_h = when h was last heard,
/// T = the timeout, arm_driver.commander_timeout, 1.6 s by default):
///
///   free ──(any command or heartbeat from S)──▶ held by S, heard at t
///   held by S ──(a command or heartbeat from S)──▶ held by S, heard at t
///   held by h ──(S ≠ h, t − t_h ≥ T: h fell silent)──▶ held by S, heard at t
///   held by h ──(S ≠ h, take_over)──▶ held by S, heard at t (taken from h)
///   held by h ──(S ≠ h otherwise)──▶ unchanged; refused: "arm commanded by 'h' (heard 0.2 s ago);
///                                     sg-arm-ctl --take-over takes it"
///   held by S ──(MODE_RELEASE from S)──▶ free       (MODE_RELEASE from another: refused)
///   held by h ──(expire(t), t − t_h ≥ T)──▶ free    (the driver's watchdog then stops the arm)
///
/// MODE_STOP is obeyed from any sender: it neither takes nor frees the lease (an operator can
/// always stop the arm); from the holder it counts as hearing from it. MODE_HEARTBEAT renews the
/// lease (or takes a free one) and does nothing else. Only kCommand and kStop go on to the
/// validator, so a refused sender's sequence numbers change nothing the holder is judged by.
///
///     CommanderLease lease(1.6);
///     LeaseDecision d = lease.offer(command.sender, command.mode, command.take_over, now);
///     if (d.verdict == LeaseVerdict::kRefused) report(d.reason);
///     else if (d.verdict == LeaseVerdict::kCommand || d.verdict == LeaseVerdict::kStop)
///       validate_and_queue(command);
///     ...
///     if (lease.held() && lease.expired(now)) stop_the_arm(lease.expire(now));   // the watchdog

#include <cstdint>
#include <limits>
#include <string>

namespace sg::arm {

/// What the lease makes of one command.
enum class LeaseVerdict {
  kCommand,   ///< the sender holds the lease (now): the command goes on to the validator
  kStop,      ///< a MODE_STOP, obeyed from anyone: it goes on to the validator
  kRenewed,   ///< a MODE_HEARTBEAT from the holder (now): nothing else to do
  kReleased,  ///< a MODE_RELEASE from the holder, or with the lease free: the lease is free
  kRefused,   ///< another sender holds the lease: nothing changed
};

struct LeaseDecision {
  LeaseVerdict verdict = LeaseVerdict::kRefused;
  std::string reason;      ///< kRefused: why, naming the holder and how long ago it was heard
  std::string taken_from;  ///< the holder that S took the lease from with take_over, else ""
  bool changed = false;    ///< the holder changed (taken, taken over, released)
};

class CommanderLease {
 public:
  /// `timeout`: seconds of silence after which the holder loses the lease (> 0).
  explicit CommanderLease(double timeout);

  /// Decides on a command of `mode` (arm_cmd_t::MODE_*) from `sender` at `t`.
  LeaseDecision offer(const std::string& sender, int8_t mode, bool take_over, double t);

  /// Frees the lease if its holder has been silent for the timeout at `t`; returns the holder
  /// that lost it, "" when nothing expired.
  std::string expire(double t);

  bool held() const { return !holder_.empty(); }
  /// The holder, "" when the lease is free.
  const std::string& holder() const { return holder_; }
  /// When the holder was last heard (meaningless when free).
  double heard() const { return heard_; }
  /// When the holder loses the lease unless heard again: heard() + timeout; +inf when free.
  double deadline() const { return held() ? deadline_ : std::numeric_limits<double>::infinity(); }
  /// The lease is held and its holder has been silent for the timeout at `t`.
  bool expired(double t) const { return held() && t >= deadline_; }
  double timeout() const { return timeout_; }

 private:
  void hold(const std::string& sender, double t);

  double timeout_;
  std::string holder_;
  double heard_ = 0;
  double deadline_ = 0;
};

}  // namespace sg::arm
