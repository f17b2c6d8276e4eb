#pragma once

/// sg-grasp without the bus: what the process does between the decoded messages and the grasp
/// machine. It takes OBJECT_TRAJECTORY, OBJECT_POSITION, ARM_STATUS and GRASP_COMMAND with their
/// receive time, and poll(now) says what to publish now. All time comes in as arguments (us since
/// the Unix epoch); the node never reads a clock, so an in-process trial on a simulated clock
/// (system/grasp_trial.cpp) drives the same logic as sg-grasp.
///
///   - GRASP_COMMAND, once require_signed_commands() was called (sg-grasp does, unless
///     --insecure-no-key): first refused, RESULT_REFUSED_UNAUTHENTICATED, when unsigned, not
///     signed with the lab key for this channel, replayed or stale (auth/command_auth.hpp);
///     such a command changes nothing the later checks use, so a forged one locks no one out.
///   - GRASP_COMMAND: refused when its `sequence` is not newer than its sender's last (a replay),
///     when `command` is not a COMMAND_* value, or when `standoff` is not finite in 0..0.5 m;
///     otherwise the machine answers (accepted, or refused by its state). Every command's answer
///     goes out on the next GRASP_STATUS (command_sequence, command_result, command_reason).
///     The last sequence of at most kMaxSenders senders is kept (the longest silent is forgotten
///     first), so no stream of made-up senders exhausts the process.
///   - OBJECT_TRAJECTORY: refused (counted by reason, never turned into a target) when it fails
///     check_trajectory(): malformed, non-finite, a point outside the workspace plus
///     settings.input_gate.margin, a bad period, too many points, times far from `now`. The
///     counts and the newest reason ride on GRASP_STATUS's message, updated at most once per
///     kRefusalNotePeriod so a flood of bad trajectories cannot flood GRASP_STATUS.
///   - ARM_COMMAND, two kinds, each at most one per poll():
///     `arm_command`, the machine's take_request(now): a new request (its utime is the newest
///     trajectory's utime, the decision's message time; `now` before any trajectory), or a
///     resend of the request in flight, the very message sent first (same sequence, utime and
///     content; the shell signs it anew);
///     `lease`, the commander lease (machine().arm_need(now)): while kWanted a MODE_HEARTBEAT
///     (sequence: the last request's, gripper KEEP, the machine's speed, utime `now`) once every
///     settings.heartbeat_period from the first poll that wants the arm; when it turns kNone one
///     MODE_RELEASE; while kSilent (ARM_STATUS silent, or the track followed gone stale) nothing,
///     so the driver's watchdog stops the arm. None before the first request. Publish
///     `arm_command` first, then `lease`.
///   - GRASP_STATUS: when the summary (state, activity, last action, outcome, message, notes)
///     or the command answer changed, and otherwise once per status period (also when `now` went
///     back in time, so a clock step cannot silence it). Its message is the machine's, then the
///     notes, "; "-separated: "ARM_STATUS silent for 1.3 s" (the summary says only "ARM_STATUS
///     silent", so the count does not make every poll a change), "ARM_COMMAND resent 2" (the
///     machine's resends()), the refusal note.
///
///     GraspNode node(geometry, settings, /*first_sequence=*/now, /*status_period=*/0.25);
///     node.require_signed_commands(key);                // the lab key (auth/lab_key.hpp)
///     node.on_command(command, now);                    // from each subscription
///     GraspNode::Output out = node.poll(now);           // from the loop, every 10 ms
///     if (out.arm_command) bus.publish("ARM_COMMAND", signed(*out.arm_command));
///     if (out.lease) bus.publish("ARM_COMMAND", signed(*out.lease));
///     if (out.status) bus.publish("GRASP_STATUS", *out.status);

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "auth/command_auth.hpp"
#include "common/change_or_period.hpp"
#include "grasp/grasp_machine.hpp"
#include "grasp/grasp_messages.hpp"
#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"
#include "stereograsp/grasp_command_t.hpp"
#include "stereograsp/grasp_status_t.hpp"
#include "stereograsp/point3_t.hpp"
#include "stereograsp/trajectory_t.hpp"

namespace sg::grasp {

class GraspNode {
 public:
  /// Senders whose last sequence is remembered.
  static constexpr std::size_t kMaxSenders = 64;
  /// Characters of a command_reason (longer ones are cut).
  static constexpr std::size_t kMaxReason = 200;
  /// The largest stand-off a GRASP_COMMAND may ask for, m.
  static constexpr double kMaxStandoff = 0.5;
  /// Seconds between updates of the refusal note on GRASP_STATUS's message.
  static constexpr double kRefusalNotePeriod = 1.0;

  /// What to publish now (ARM_COMMAND unsigned: the shell signs each).
  struct Output {
    std::optional<stereograsp::arm_cmd_t> arm_command;  ///< ARM_COMMAND: a request, or a resend
    std::optional<stereograsp::arm_cmd_t> lease;  ///< ARM_COMMAND MODE_HEARTBEAT / MODE_RELEASE
    std::optional<stereograsp::grasp_status_t> status;  ///< GRASP_STATUS
    std::string changed_summary;  ///< the new summary when it changed (for the log), else ""
  };

  /// `first_sequence`: the first ARM_COMMAND's sequence; `status_period`: s between
  /// GRASP_STATUS messages when nothing changes (> 0).
  GraspNode(ArmGeometry geometry, GraspSettings settings, int64_t first_sequence,
            double status_period);

  /// An OBJECT_TRAJECTORY received at `now`. Returns "" when the machine took it, else why it
  /// was refused (check_trajectory(); counted in refused_trajectories()).
  std::string on_trajectory(const stereograsp::trajectory_t& trajectory, int64_t now);
  /// OBJECT_TRAJECTORY refused for `reason` so far.
  uint64_t refused_trajectories(TrajectoryRefusal reason) const {
    return refused_[static_cast<size_t>(reason)];
  }
  /// "OBJECT_TRAJECTORY refused 3 (non-finite 2, time far from now 1); last: <why>", "" if none.
  std::string refusal_note() const;

  /// An OBJECT_POSITION: the measurement at its utime (not visible or not finite: none).
  void on_position(const stereograsp::point3_t& position);

  /// The capture clock (whose times trajectories and positions carry) minus this host's clock,
  /// µs (grasp/capture_clock.hpp): their times are put on this host's clock before anything uses
  /// them, so a host whose clock is off does not move every interception by as much. 0 by
  /// default (one clock).
  void set_capture_clock_offset(int64_t offset_us) { capture_offset_ = offset_us; }
  int64_t capture_clock_offset() const { return capture_offset_; }

  /// An ARM_STATUS received at `now`.
  void on_arm_status(const stereograsp::arm_status_t& status, int64_t now);

  /// From now on, GRASP_COMMAND must be signed with `key` for `channel` (the channel the
  /// commands arrive on); `settings`: the verifier's maximum age and sender table.
  void require_signed_commands(const auth::LabKey& key, std::string channel = "GRASP_COMMAND",
                               auth::VerifierSettings settings = {});
  /// The verifier of require_signed_commands() (its counts), nullptr before.
  const auth::CommandVerifier* command_verifier() const {
    return verifier_ ? &*verifier_ : nullptr;
  }

  /// A GRASP_COMMAND received at `now`: the signature (when required), the sequence and range
  /// checks, then the machine.
  /// Returns the answer that the next GRASP_STATUS carries.
  const CommandRecord& on_command(const stereograsp::grasp_command_t& command, int64_t now);

  /// What to publish at `now`: at most one request (or resend) and one heartbeat or release,
  /// and GRASP_STATUS on a change or when the status period has passed.
  Output poll(int64_t now);

  /// MODE_HEARTBEAT and MODE_RELEASE sent so far.
  uint64_t heartbeats() const { return heartbeats_; }
  uint64_t releases() const { return releases_; }

  const GraspMachine& machine() const { return machine_; }
  /// The answer to the last command (sequence -1 before any).
  const CommandRecord& last_command() const { return command_; }

  /// "q3 hand closed, grasping, last a2 close hand, outcome none: <message>".
  static std::string summary(const GraspStatusView& view);

 private:
  struct Sender {
    int64_t sequence = 0;
    int64_t heard_utime = 0;
  };

  /// Records the answer to command `sequence` (its reason made short ASCII).
  const CommandRecord& answer(int64_t sequence, CommandResult result, std::string reason);
  /// Checks `command`'s sequence against its sender's last; true when newer (or first).
  bool newer(const stereograsp::grasp_command_t& command, int64_t now, std::string* why);
  /// The heartbeat or release due at `now`, if any.
  std::optional<stereograsp::arm_cmd_t> lease_command(int64_t now);
  /// The notes GRASP_STATUS's message carries after the machine's; `exact`: with the numbers
  /// that change by themselves (the silence), else without (for the summary).
  std::vector<std::string> notes(int64_t now, bool exact) const;

  arm::Workspace workspace_;  ///< the arm's, for the trajectory gate (before machine_ takes it)
  InputGate gate_;
  double heartbeat_period_;  ///< s
  double speed_;             ///< the heartbeats' speed (the machine's)
  GraspMachine machine_;
  ChangeOrPeriod status_rule_;    ///< GRASP_STATUS on a change, else once a period
  uint64_t status_version_ = 0;   ///< counts the changes of the summary and the command answer
  int64_t trajectory_utime_ = 0;  ///< the newest OBJECT_TRAJECTORY's utime (0: none yet)
  std::map<std::string, Sender> senders_;
  std::optional<auth::CommandVerifier> verifier_;  ///< set by require_signed_commands()
  std::string command_channel_;
  CommandRecord command_;
  /// The command command_ answers, once verified (not after a refused signature): an identical
  /// message again is a resend.
  std::optional<stereograsp::grasp_command_t> resend_of_last_;
  bool command_changed_ = false;
  std::string last_summary_;
  std::array<uint64_t, kTrajectoryRefusals> refused_{};
  int64_t capture_offset_ = 0;
  std::string last_refusal_;
  bool refusals_changed_ = false;
  std::string note_;                            ///< refusal_note() as last put on GRASP_STATUS
  int64_t note_utime_ = 0;                      ///< when note_ was updated
  std::optional<stereograsp::arm_cmd_t> sent_;  ///< the last request as first sent
  bool holding_ = false;                        ///< a heartbeat went out since the last release
  int64_t heartbeat_utime_ = 0;                 ///< when the last heartbeat went out
  uint64_t heartbeats_ = 0;
  uint64_t releases_ = 0;
};

}  // namespace sg::grasp
