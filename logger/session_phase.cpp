#include "logger/session_phase.hpp"

#include <algorithm>

#include "common/message_types.hpp"

namespace sg::logger {
namespace {

using Status = stereograsp::grasp_status_t;

}  // namespace

const char* phase_name(Phase phase) {
  static const char* const names[] = {"no grasp machine", "calibration", "idle",
                                      "tracking",         "approach",    "carried"};
  return names[static_cast<int>(phase)];
}

const char* phase_key(Phase phase) {
  static const char* const keys[] = {"no_grasp_machine", "calibration", "idle",
                                     "tracking",         "approach",    "carried"};
  return keys[static_cast<int>(phase)];
}

Phase SessionPhase::rule() const {
  const bool sim = have_sim_ && last_recv_ - sim_recv_ <= kSimFresh;
  if (!have_grasp_) {
    if (sim) return holding_ ? Phase::kCalibration : Phase::kNoGraspMachine;
    return arm_commanded_ ? Phase::kCalibration : Phase::kNoGraspMachine;
  }
  const bool closed = state_ == Status::Q3_HAND_CLOSED || state_ == Status::Q4_OBJECT_LIFTED;
  if (sim ? holding_ : closed) return Phase::kCarried;
  if (state_ == Status::Q2_GRASPING) return Phase::kApproach;
  if (state_ == Status::Q1_APPROACHING) return Phase::kTracking;
  if (state_ == Status::Q0_HAND_OPENED && activity_ == Status::ACTIVITY_TRACKING)
    return Phase::kTracking;
  return Phase::kIdle;
}

bool SessionPhase::update(int64_t recv) {
  const Phase next = rule();
  if (next == current_ && !changes_.empty()) return false;
  current_ = next;
  changes_.emplace_back(recv, next);
  if (changes_.size() > kMaxChanges) {
    changes_.pop_front();
    trimmed_ = true;
  }
  return true;
}

bool SessionPhase::advance(int64_t recv) {
  if (!started_) {
    started_ = true;
    last_recv_ = recv;
    return update(recv);
  }
  if (recv > last_recv_) {
    // In double: recv - last_recv_ overflows int64 for times a hostile log can hold.
    time_in_[static_cast<int>(current_)] +=
        static_cast<double>(recv) - static_cast<double>(last_recv_);
    last_recv_ = recv;
  }
  return update(last_recv_);
}

bool SessionPhase::on_grasp_status(int64_t recv, int state, int activity) {
  advance(recv);
  have_grasp_ = true;
  state_ = state;
  activity_ = activity;
  return update(last_recv_);
}

bool SessionPhase::on_sim_arm_state(int64_t recv, bool holding) {
  advance(recv);
  have_sim_ = true;
  holding_ = holding;
  sim_recv_ = last_recv_;
  return update(last_recv_);
}

bool SessionPhase::on_arm_command(int64_t recv) {
  advance(recv);
  arm_commanded_ = true;
  return update(last_recv_);
}

std::optional<Phase> SessionPhase::at(int64_t recv) const {
  const auto after = std::upper_bound(
      changes_.begin(), changes_.end(), recv,
      [](int64_t t, const std::pair<int64_t, Phase>& change) { return t < change.first; });
  if (after == changes_.begin()) {
    // Before the first change kept: unknown when older ones were dropped, else before the log.
    if (trimmed_ || changes_.empty()) return std::nullopt;
    return changes_.front().second;
  }
  return std::prev(after)->second;
}

double SessionPhase::seconds_in(Phase phase) const {
  return time_in_[static_cast<int>(phase)] * 1e-6;
}

}  // namespace sg::logger
