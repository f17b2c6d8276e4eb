#pragma once

/// The driver core: validated commands go into a latest-wins slot, one interaction with the
/// controller is in flight at a time, and the status is kept for the bus. The controller answers
/// one interaction every 0.72-0.84 s, so a command that arrives meanwhile replaces the pending one
/// (never a backlog), and no command is executed twice: a command counts as executed once its CR
/// has reached the controller.
///
/// One commander at a time (docs/arm.md, "One commander and the watchdog"): every command first
/// passes the CommanderLease; only the holder's commands (and a STOP from anyone) reach the
/// validator. MODE_HEARTBEAT and MODE_RELEASE touch only the lease: they consume no sequence and
/// leave last_received_sequence and the pending slot alone. A command whose sequence equals its
/// sender's last is a duplicate (a resend): ignored, executed once. The watchdog: when the holder
/// has been silent for settings.commander_timeout the lease expires, and if the arm moves or a
/// motion is pending the pending slot gets the driver's own STOP (ABORT, the gripper kept as it
/// is), which ARM_STATUS reports in `watchdog` and `error` without a sequence of its own.
///
/// A gripper action gives way. A motion command (MODE_CARTESIAN, MODE_JOINTS, MODE_HOME) that
/// carries a gripper action sends the motion, waits for its reply (one interaction), then sends
/// the gripper action: but if by then a newer command waits in the slot, the gripper action is
/// not sent. The command counts as executed (its motion ran) with the gripper as it was, and the
/// newer command goes next. This is latest wins applied to the half of a command not yet on the
/// line: an approach's CLOSE sent from a forecast that a turn has since overtaken gives way to
/// the re-planned approach (GraspMachine, "Re-planning"), and a watchdog's STOP to a closing hand
/// is obeyed one interaction sooner. A STOP's OPEN and a MODE_GRIPPER_ONLY action are always sent.
///
///     ArmDriver driver(geometry, settings, [&] { return SerialPort::open(path, serial); });
///     std::jthread worker([&](std::stop_token stop) { driver.run(stop); });
///     Submission s = driver.submit(command);        // from the bus thread
///     if (s.outcome == Submission::kRefused) bus.note_refused("ARM_COMMAND", s.reason);
///     auto [status, version] = driver.status();     // publish when version changes

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>

#include "arm_driver/byte_stream.hpp"
#include "arm_driver/c550_link.hpp"
#include "arm_driver/command_validator.hpp"
#include "arm_driver/commander_lease.hpp"
#include "arm_driver/log_limiter.hpp"
#include "common/clock.hpp"
#include "stereograsp/arm_status_t.hpp"

namespace sg::arm {

struct DriverSettings {
  int slave = 1;
  LinkTiming timing;
  double moving_poll = 0.1;         ///< s between W2 reads while the arm moves and nothing waits
  double idle_poll = 0.5;           ///< s between W2 reads at rest (also notices a lost line)
  double reconnect_min = 0.2;       ///< s, first wait before reconnecting; doubles ...
  double reconnect_max = 2.0;       ///< ... up to this
  double arrived_tolerance = 1e-3;  ///< rad: within this of the target, the arm is IDLE
  int max_attempts = 3;             ///< sends of an undelivered command before it is rejected
  /// The fastest the driver lets the arm move, a fraction of the joints' maximum speeds: the
  /// SPEED sent is min(command's speed, max_speed) in whole percent, 1..100 (a lab's cap).
  double max_speed = 1.0;
  /// s of silence after which the commander loses the lease and the watchdog stops a moving arm:
  /// about two controller interactions of 0.72-0.84 s.
  double commander_timeout = 1.6;
  /// When the driver process started, us since the Unix epoch (ARM_STATUS.driver_start_utime);
  /// 0: the clock's utime() when the ArmDriver is made. Not a configuration key.
  int64_t start_utime = 0;
};

/// What submit() made of a command.
struct Submission {
  enum Outcome {
    kQueued,     ///< validated and in the slot (it replaced any pending command)
    kDuplicate,  ///< its sequence equals its sender's last: ignored, not executed again
    kRejected,   ///< the validator rejected it (status: last_rejected_sequence, the reason)
    kRefused,    ///< the lease refused it: another sender commands the arm
    kLease,      ///< a heartbeat or release: the lease renewed, taken or freed; nothing else
  };
  Outcome outcome = kQueued;
  std::string reason;  ///< kRejected, kRefused: why
};

using DeviceOpener = std::function<std::unique_ptr<ByteStream>()>;

class ArmDriver {
 public:
  /// Validates with `geometry`, opens the line with `open_device` (again after it is lost), and
  /// takes all time from `clock`: the machine's in sg-arm-driver, a SimulatedClock in trials.
  ArmDriver(ArmGeometry geometry, DriverSettings settings, DeviceOpener open_device,
            Clock& clock = system_clock());

  /// Passes a command (bus thread, authenticated already) through the lease, then validates it
  /// and puts it in the slot, or records its rejection or refusal (a heartbeat's or release's
  /// refusal is only returned: it has no sequence of its own to report).
  Submission submit(const stereograsp::arm_cmd_t& command);

  /// Records a command refused before validation (e.g. unauthenticated: `why`) as rejected in
  /// the status, leaving what judges later commands untouched: last_received_sequence, the
  /// validator's per-sender sequence and the pending command.
  void refuse(const stereograsp::arm_cmd_t& command, const std::string& why);

  /// The status with utime unset, and a version that changes with every change.
  std::pair<stereograsp::arm_status_t, uint64_t> status() const;

  /// The worker: connects (and reconnects with back-off), runs interactions, polls the joints.
  void run(std::stop_token stop);

  /// Driver time spent per interaction outside the serial line (validation excluded): for the
  /// benchmark; seconds, of the last interaction.
  double last_overhead() const;

  /// Gripper actions of motion commands not sent because a newer command waited (see the file
  /// comment, "A gripper action gives way").
  uint64_t gripper_actions_dropped() const;

 private:
  Submission queue(const stereograsp::arm_cmd_t& command);
  Submission refuse_by_lease(const stereograsp::arm_cmd_t& command, const std::string& why);
  void note_lease_change(const std::string& sender, const LeaseDecision& decision);
  /// Under mutex_: expires a silent commander's lease at `t`, and stops the arm if it moves or
  /// a motion is pending.
  void watchdog(double t);
  bool connect(std::stop_token stop);
  void disconnect(const std::string& why);
  void execute(ArmTarget target);
  void send_speed(const ArmTarget& target);
  /// Sends the target's motion, then its gripper action unless superseded(): then the target's
  /// gripper becomes GRIPPER_KEEP (what was executed).
  void act(ArmTarget& target);
  /// Whether a motion's gripper action, not yet sent, gives way to a newer command waiting in
  /// the slot (counted and logged).
  bool superseded(const ArmTarget& target);
  void requeue_rest(ArmTarget target);
  void record_executed(const ArmTarget& target);
  void record_refusal(const ArmTarget& target, const std::string& why);
  void read_joints();
  std::optional<ArmTarget> wait_for_work(std::stop_token stop);
  void requeue(ArmTarget target);
  template <class F>
  void update(F&& change);

  CommandValidator validator_;
  CommanderLease lease_;
  LogLimiter log_limit_;
  DriverSettings settings_;
  DeviceOpener open_device_;
  std::unique_ptr<ByteStream> stream_;
  std::unique_ptr<C550Link> link_;
  int speed_percent_ = -1;  ///< the controller's SPEED, -1 before the first
  int attempts_ = 0;          ///< sends of the pending command that did not reach the controller
  bool motion_done_ = false;  ///< this interaction's motion command has been delivered

  Clock& clock_;
  mutable std::mutex mutex_;
  std::optional<ArmTarget> pending_;
  std::optional<Joints> commanded_;  ///< the last joint target sent
  Joints current_ = Joints::Zero();
  bool have_read_ = false;  ///< current_ was read from the controller (since the start)
  stereograsp::arm_status_t status_;
  uint64_t version_ = 0;
  double overhead_ = 0;
  uint64_t gripper_actions_dropped_ = 0;
};

/// Copies joints and the tool pose (forward kinematics) into a status.
void set_joints(const ArmGeometry& geometry, const Joints& q, stereograsp::arm_status_t& status);

}  // namespace sg::arm
