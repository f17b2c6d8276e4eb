#include "grasp/grasp_messages.hpp"

#include <cmath>
#include <cstdio>

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
  v.gripper = s.gripper;
  v.last_received_sequence = s.last_received_sequence;
  v.last_executed_sequence = s.last_executed_sequence;
  v.last_rejected_sequence = s.last_rejected_sequence;
  v.rejection_reason = s.rejection_reason;
  v.driver_start_utime = s.driver_start_utime;
  v.watchdog = s.watchdog;
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

namespace {

/// path_from(), with the kind of refusal in `kind`.
std::optional<PredictedPath> convert(const stereograsp::trajectory_t& m, TrajectoryRefusal* kind,
                                     std::string* why) {
  const auto refuse = [&](TrajectoryRefusal k,
                          const std::string& reason) -> std::optional<PredictedPath> {
    *kind = k;
    if (why) *why = reason;
    return std::nullopt;
  };
  PredictedPath p;
  p.utime = m.utime;
  p.start_utime = m.start_utime;
  p.period_us = m.period_us;
  p.lost = m.status == stereograsp::trajectory_t::STATUS_LOST;
  if (m.period_us <= 0) {
    return refuse(TrajectoryRefusal::kBadPeriod, "period " + std::to_string(m.period_us) + " us");
  }
  if (m.num_points < 0 || static_cast<size_t>(m.num_points) != m.position.size()) {
    return refuse(TrajectoryRefusal::kMalformed, "num_points " + std::to_string(m.num_points) +
                                                     " for " + std::to_string(m.position.size()) +
                                                     " points");
  }
  for (const auto& q : m.position) {
    if (q.size() == 3 && std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2])) {
      p.points.emplace_back(q[0], q[1], q[2]);
    } else if (p.lost) {
      break;  // a lost track may carry NaNs
    } else {
      return refuse(TrajectoryRefusal::kNonFinite,
                    "point " + std::to_string(p.points.size()) + " is not 3 finite numbers");
    }
  }
  if (m.position_sigma.size() != m.position.size()) {
    return refuse(TrajectoryRefusal::kMalformed, std::to_string(m.position_sigma.size()) +
                                                     " sigmas for " +
                                                     std::to_string(m.position.size()) + " points");
  }
  for (size_t i = 0; i < p.points.size(); ++i) {  // a lost track's NaNs are cut off above
    const auto& s = m.position_sigma[i];
    if (s.size() != 3 || !(s[0] >= 0 && s[1] >= 0 && s[2] >= 0) ||
        !(std::isfinite(s[0]) && std::isfinite(s[1]) && std::isfinite(s[2]))) {
      return refuse(TrajectoryRefusal::kNonFinite,
                    "sigma " + std::to_string(i) + " is not 3 finite numbers >= 0");
    }
    p.sigmas.emplace_back(s[0], s[1], s[2]);
  }
  return p;
}

}  // namespace

std::optional<PredictedPath> path_from(const stereograsp::trajectory_t& m, std::string* why) {
  TrajectoryRefusal kind;
  return convert(m, &kind, why);
}

const char* to_string(TrajectoryRefusal reason) {
  switch (reason) {
    case TrajectoryRefusal::kMalformed:
      return "malformed";
    case TrajectoryRefusal::kNonFinite:
      return "non-finite";
    case TrajectoryRefusal::kOutsideWorkspace:
      return "outside the workspace";
    case TrajectoryRefusal::kBadPeriod:
      return "bad period";
    case TrajectoryRefusal::kTooManyPoints:
      return "too many points";
    case TrajectoryRefusal::kTimeFarFromNow:
      return "time far from now";
  }
  return "?";
}

namespace {

std::string xyz(const Eigen::Vector3d& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.4g, %.4g, %.4g)", p.x(), p.y(), p.z());
  return text;
}

/// "" when `t` (a message time, us) is plausible at `now`, else why not.
std::string time_problem(const char* name, int64_t t, int64_t now, double max_offset) {
  const double offset = (static_cast<double>(t) - static_cast<double>(now)) * 1e-6;
  if (t <= 0 || t > kLatestUtime) return std::string(name) + " " + std::to_string(t) + " us";
  if (max_offset > 0 && !(std::abs(offset) <= max_offset)) {
    return std::string(name) + " is " + std::to_string(offset) + " s from the receiver's clock";
  }
  return "";
}

/// The checks before path_from(): the ones that bound what path_from() walks and computes.
std::optional<std::pair<TrajectoryRefusal, std::string>> header_problem(
    const stereograsp::trajectory_t& m, const InputGate& gate, int64_t now) {
  using R = TrajectoryRefusal;
  if (m.period_us < kMinPeriodUs || m.period_us > kMaxPeriodUs) {
    return std::pair{R::kBadPeriod, "period " + std::to_string(m.period_us) + " us (1 ms to 60 s)"};
  }
  if (m.num_points > kMaxTrajectoryPoints) {
    return std::pair{R::kTooManyPoints, "num_points " + std::to_string(m.num_points) +
                                            " (at most " + std::to_string(kMaxTrajectoryPoints) +
                                            ")"};
  }
  for (const auto& [name, t] : {std::pair{"utime", m.utime}, {"start_utime", m.start_utime}}) {
    if (std::string p = time_problem(name, t, now, gate.max_time_offset); !p.empty()) {
      return std::pair{R::kTimeFarFromNow, std::move(p)};
    }
  }
  return std::nullopt;
}

}  // namespace

TrajectoryCheck check_trajectory(const stereograsp::trajectory_t& m,
                                 const arm::Workspace& workspace, const InputGate& gate,
                                 int64_t now) {
  TrajectoryCheck c;
  if (auto problem = header_problem(m, gate, now)) {
    c.reason = problem->first, c.why = std::move(problem->second);
    return c;
  }
  std::optional<PredictedPath> path = convert(m, &c.reason, &c.why);
  if (!path) return c;
  if (!path->lost) {
    const Eigen::Vector3d lo = workspace.min.array() - gate.margin;
    const Eigen::Vector3d hi = workspace.max.array() + gate.margin;
    for (size_t i = 0; i < path->points.size(); ++i) {
      const Eigen::Vector3d& q = path->points[i];
      if (!((q.array() >= lo.array()).all() && (q.array() <= hi.array()).all())) {
        c.reason = TrajectoryRefusal::kOutsideWorkspace;
        c.why = "point " + std::to_string(i) + " " + xyz(q) + " m outside the workspace " +
                xyz(lo) + " .. " + xyz(hi) + " m";
        return c;
      }
    }
  }
  c.path = std::move(path);
  c.why.clear();
  return c;
}

}  // namespace sg::grasp
