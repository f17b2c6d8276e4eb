#include "grasp/grasp_node.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace sg::grasp {
namespace {

/// `text` as printable ASCII (anything else '?'), at most `limit` characters.
std::string ascii(const std::string& text, std::size_t limit) {
  std::string out = text.substr(0, limit);
  for (char& c : out) {
    if (c < 0x20 || c > 0x7e) c = '?';
  }
  return out;
}

}  // namespace

GraspNode::GraspNode(ArmGeometry geometry, GraspSettings settings, int64_t first_sequence,
                     double status_period)
    : workspace_(geometry.workspace),
      gate_(settings.input_gate),
      heartbeat_period_(settings.heartbeat_period),
      speed_(settings.speed),
      machine_(std::move(geometry), std::move(settings), first_sequence),
      status_rule_(status_period) {}

std::string GraspNode::on_trajectory(const stereograsp::trajectory_t& received, int64_t now) {
  stereograsp::trajectory_t shifted;
  const bool shift = capture_offset_ != 0;
  if (shift) {  // onto this host's clock; a time so absurd it would overflow is left to the check
    shifted = received;
    for (int64_t* t : {&shifted.utime, &shifted.source_utime, &shifted.start_utime}) {
      int64_t local = 0;
      if (!__builtin_sub_overflow(*t, capture_offset_, &local)) *t = local;
    }
  }
  const stereograsp::trajectory_t& trajectory = shift ? shifted : received;
  TrajectoryCheck c = check_trajectory(trajectory, workspace_, gate_, now);
  if (!c.path) {
    ++refused_[static_cast<size_t>(c.reason)];
    last_refusal_ = ascii(c.why, kMaxReason);
    refusals_changed_ = true;
    return c.why;
  }
  trajectory_utime_ = trajectory.utime;
  machine_.on_trajectory(*c.path, trajectory.source_utime, now);
  return "";
}

std::string GraspNode::refusal_note() const {
  uint64_t total = 0;
  std::string each;
  for (int i = 0; i < kTrajectoryRefusals; ++i) {
    const uint64_t n = refused_[static_cast<size_t>(i)];
    if (n == 0) continue;
    total += n;
    each += (each.empty() ? "" : ", ") + std::string(to_string(static_cast<TrajectoryRefusal>(i))) +
            " " + std::to_string(n);
  }
  if (total == 0) return "";
  return "OBJECT_TRAJECTORY refused " + std::to_string(total) + " (" + each +
         "); last: " + last_refusal_;
}

void GraspNode::on_position(const stereograsp::point3_t& m) {
  const Eigen::Vector3d p(m.position[0], m.position[1], m.position[2]);
  int64_t utime = 0;
  if (__builtin_sub_overflow(m.utime, capture_offset_, &utime)) utime = m.utime;
  machine_.on_measurement(m.visible && p.allFinite() ? std::optional(p) : std::nullopt, utime);
}

void GraspNode::on_arm_status(const stereograsp::arm_status_t& status, int64_t now) {
  machine_.on_arm_status(arm_view_of(status), now);
}

void GraspNode::require_signed_commands(const auth::LabKey& key, std::string channel,
                                        auth::VerifierSettings settings) {
  verifier_.emplace(key, settings);
  command_channel_ = std::move(channel);
}

const CommandRecord& GraspNode::on_command(const stereograsp::grasp_command_t& m, int64_t now) {
  // A resend of the command last answered, by the sender it was verified from (sg-grasp-ctl
  // resends until it hears the answer: the bus may lose the command or the answer): the same
  // answer again, on the next GRASP_STATUS; nothing is verified or carried out twice.
  if (resend_of_last_ && m.sequence == command_.sequence && m.sender == resend_of_last_->sender &&
      m.command == resend_of_last_->command && m.standoff == resend_of_last_->standoff &&
      m.auth_counter == resend_of_last_->auth_counter) {
    command_changed_ = true;
    return command_;
  }
  resend_of_last_.reset();
  if (verifier_) {
    const auth::Verification v = verifier_->verify(command_channel_, m, now);
    if (!v.accepted()) {
      return answer(m.sequence, CommandResult::kRefusedUnauthenticated,
                    "unauthenticated: " + v.reason);
    }
  }
  resend_of_last_ = m;
  std::string why;
  if (!newer(m, now, &why)) return answer(m.sequence, CommandResult::kRefusedNotNewer, why);
  if (m.command < stereograsp::grasp_command_t::COMMAND_TRACK ||
      m.command > stereograsp::grasp_command_t::COMMAND_HOME) {
    return answer(m.sequence, CommandResult::kRefusedUnknownCommand,
                  "unknown command " + std::to_string(static_cast<int>(m.command)));
  }
  if (!(std::isfinite(m.standoff) && m.standoff >= 0 && m.standoff <= kMaxStandoff)) {
    return answer(m.sequence, CommandResult::kRefusedBadArgument,
                  "stand-off " + std::to_string(m.standoff) + " m outside 0..0.5 m");
  }
  CommandReply reply = machine_.on_command(static_cast<GraspCommand>(m.command), m.standoff, now);
  return answer(m.sequence, reply.result, std::move(reply.reason));
}

bool GraspNode::newer(const stereograsp::grasp_command_t& m, int64_t now, std::string* why) {
  const auto it = senders_.find(m.sender);
  if (it != senders_.end()) {
    it->second.heard_utime = now;
    if (m.sequence <= it->second.sequence) {
      *why = "sequence " + std::to_string(m.sequence) + " from '" + m.sender + "' not newer than " +
             std::to_string(it->second.sequence);
      return false;
    }
    it->second.sequence = m.sequence;
    return true;
  }
  if (senders_.size() >= kMaxSenders) {  // forget the longest silent
    senders_.erase(std::min_element(senders_.begin(), senders_.end(), [](auto& a, auto& b) {
      return a.second.heard_utime < b.second.heard_utime;
    }));
  }
  senders_.emplace(m.sender, Sender{m.sequence, now});
  return true;
}

const CommandRecord& GraspNode::answer(int64_t sequence, CommandResult result, std::string reason) {
  command_.sequence = sequence;
  command_.reply.result = result;
  command_.reply.reason = ascii(reason, kMaxReason);
  command_changed_ = true;
  return command_;
}

GraspNode::Output GraspNode::poll(int64_t now) {
  Output out;
  if (std::optional<ArmRequest> request = machine_.take_request(now)) {
    if (!sent_ || sent_->sequence != request->sequence) {  // new; else a resend, the same message
      sent_ = to_arm_cmd(*request, trajectory_utime_ ? trajectory_utime_ : now);
    }
    out.arm_command = sent_;
  }
  out.lease = lease_command(now);
  // The refusal note changes at most once per kRefusalNotePeriod (or when the clock went back).
  if (refusals_changed_ &&
      (now - note_utime_ >= static_cast<int64_t>(kRefusalNotePeriod * 1e6) || now < note_utime_)) {
    note_ = refusal_note();
    note_utime_ = now;
    refusals_changed_ = false;
  }
  std::string s = summary(machine_.status());
  for (const std::string& note : notes(now, false)) s += " [" + note + "]";
  const bool changed = s != last_summary_;
  if (changed || command_changed_) ++status_version_;
  if (status_rule_.due(status_version_, static_cast<double>(now) * 1e-6)) {
    out.status = to_grasp_status(machine_.status(), now, command_);
    std::string& message = out.status->message;
    for (const std::string& note : notes(now, true))
      message += (message.empty() ? "" : "; ") + note;
    if (changed) out.changed_summary = s;
    last_summary_ = s;
    command_changed_ = false;
  }
  return out;
}

std::optional<stereograsp::arm_cmd_t> GraspNode::lease_command(int64_t now) {
  if (!sent_) return std::nullopt;  // no request yet: nothing to keep
  using Cmd = stereograsp::arm_cmd_t;
  int8_t mode = 0;
  switch (machine_.arm_need(now)) {
    case ArmNeed::kWanted: {
      const int64_t since = now - heartbeat_utime_;
      if (holding_ && since >= 0 && since < std::llround(heartbeat_period_ * 1e6)) {
        return std::nullopt;
      }
      holding_ = true;
      heartbeat_utime_ = now;
      ++heartbeats_;
      mode = Cmd::MODE_HEARTBEAT;
      break;
    }
    case ArmNeed::kSilent:  // the driver's watchdog stops the arm
      return std::nullopt;
    case ArmNeed::kNone:
      if (!holding_) return std::nullopt;
      holding_ = false;
      ++releases_;
      mode = Cmd::MODE_RELEASE;
      break;
  }
  Cmd c{};
  c.utime = now;
  c.sequence = sent_->sequence;  // the last request's: a heartbeat consumes no sequence
  c.mode = mode;
  c.gripper = Cmd::GRIPPER_KEEP;
  c.speed = speed_;
  c.sender = sent_->sender;
  return c;
}

std::vector<std::string> GraspNode::notes(int64_t now, bool exact) const {
  std::vector<std::string> out;
  if (const std::optional<double> silence = machine_.arm_status_silence(now)) {
    char text[64];
    std::snprintf(text, sizeof text, "ARM_STATUS silent for %.1f s", *silence);
    out.emplace_back(exact ? text : "ARM_STATUS silent");
  }
  if (machine_.resends() > 0)
    out.push_back("ARM_COMMAND resent " + std::to_string(machine_.resends()));
  if (!note_.empty()) out.push_back(note_);
  return out;
}

std::string GraspNode::summary(const GraspStatusView& v) {
  return std::string(to_string(v.state)) + ", " + to_string(v.activity) + ", last " +
         to_string(v.last_action) + ", outcome " + to_string(v.outcome) +
         (v.message.empty() ? "" : ": " + v.message);
}

}  // namespace sg::grasp
