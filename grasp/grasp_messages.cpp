#include "grasp/grasp_messages.hpp"

#include <cmath>

namespace sg::grasp {

stereograsp::arm_cmd_t to_arm_cmd(const ArmRequest& r, int64_t utime, const std::string& sender) {
  stereograsp::arm_cmd_t c{};
  c.utime = utime;
  c.source_utime = r.source_utime;
  c.target_utime = r.target_utime;
  c.sequence = r.sequence;
  c.mode = r.mode;
  for (int i = 0; i < 3; ++i) c.position[i] = r.position[i], c.orientation[i] = r.rpy[i];
  c.gripper = r.gripper;
  c.speed = r.speed;
  c.sender = sender;
  return c;
}

ArmView arm_view_of(const stereograsp::arm_status_t& s) {
  using S = stereograsp::arm_status_t;
  ArmView v;
  v.connected = s.state != S::STATE_DISCONNECTED;
  v.moving = s.state == S::STATE_MOVING;
  v.error = s.state == S::STATE_ERROR;
  v.last_executed_sequence = s.last_executed_sequence;
  v.last_rejected_sequence = s.last_rejected_sequence;
  for (int i = 0; i < 6; ++i) v.joints[i] = s.joints[i];
  v.tool = {s.tool_position[0], s.tool_position[1], s.tool_position[2]};
  v.interaction_time = s.interaction_time;
  return v;
}

stereograsp::grasp_status_t to_grasp_status(const GraspStatusView& v, int64_t utime,
                                            const CommandRecord& command) {
  stereograsp::grasp_status_t m{};
  m.utime = utime;
  m.source_utime = v.source_utime;
  m.state = static_cast<int8_t>(v.state);
  m.activity = static_cast<int8_t>(v.activity);
  m.last_action = static_cast<int8_t>(v.last_action);
  for (int i = 0; i < 3; ++i) m.target[i] = v.target ? (*v.target)[i] : std::nan("");
  m.target_utime = v.target_utime;
  m.outcome = static_cast<int8_t>(v.outcome);
  m.message = v.message;
  m.command_sequence = command.sequence;
  m.command_result = static_cast<int8_t>(command.reply.result);
  m.command_reason = command.reply.reason;
  return m;
}

std::optional<PredictedPath> path_from(const stereograsp::trajectory_t& m, std::string* why) {
  const auto refuse = [&](const std::string& reason) -> std::optional<PredictedPath> {
    if (why) *why = reason;
    return std::nullopt;
  };
  PredictedPath p;
  p.utime = m.utime;
  p.start_utime = m.start_utime;
  p.period_us = m.period_us;
  p.lost = m.status == stereograsp::trajectory_t::STATUS_LOST;
  if (m.period_us <= 0) return refuse("period " + std::to_string(m.period_us) + " us");
  if (m.num_points < 0 || static_cast<size_t>(m.num_points) != m.position.size()) {
    return refuse("num_points " + std::to_string(m.num_points) + " for " +
                  std::to_string(m.position.size()) + " points");
  }
  for (const auto& q : m.position) {
    if (q.size() == 3 && std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2])) {
      p.points.emplace_back(q[0], q[1], q[2]);
    } else if (p.lost) {
      break;  // a lost track may carry NaNs
    } else {
      return refuse("point " + std::to_string(p.points.size()) + " is not 3 finite numbers");
    }
  }
  return p;
}

}  // namespace sg::grasp
