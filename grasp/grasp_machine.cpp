#include "grasp/grasp_machine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "common/grasp_names.hpp"
#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"

namespace sg::grasp {

using arm::forward_kinematics;
using arm::motion_time;
using arm::rpy_from_rotation;
namespace {

using Cmd = stereograsp::arm_cmd_t;
using Status = stereograsp::arm_status_t;

/// Microseconds in `seconds`, rounded to the nearest.
int64_t to_us(double seconds) { return std::llround(seconds * 1e6); }

/// `value` with `digits` decimals.
std::string fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
  return buffer;
}

/// How many commands of a request the controller digests for one delay each (MA, READY, OPEN,
/// CLOSE; ABORT is not one).
int motion_commands(int8_t mode, int8_t gripper) {
  const int motion = (mode == Cmd::MODE_CARTESIAN || mode == Cmd::MODE_HOME) ? 1 : 0;
  return motion + (gripper != Cmd::GRIPPER_KEEP ? 1 : 0);
}

/// Sequence numbers kept for the delay learning (an answer comes within a couple of requests).
constexpr std::size_t kRememberedRequests = 16;

/// What a rejection reason says of the commander lease: "arm commanded by '<holder>'" (at most
/// kMaxHolder characters of the holder, printable ASCII), "" when it says nothing of it.
constexpr std::size_t kMaxHolder = 100;
std::string lease_holder_note(const std::string& reason) {
  static const std::string kKey = "arm commanded by '";
  const std::size_t at = reason.find(kKey);
  if (at == std::string::npos) return "";
  const std::size_t from = at + kKey.size();
  const std::size_t end = reason.find('\'', from);
  std::string holder = reason.substr(
      from, std::min(end == std::string::npos ? reason.size() : end, from + kMaxHolder) - from);
  for (char& c : holder) {
    if (c < 0x20 || c > 0x7e || c == '\'') c = '?';
  }
  return "arm commanded by '" + holder + "'";
}

/// The message while the track followed is stale (GraspNode stops the heartbeats).
const char* const kStaleTrack =
    "no fresh track of the object: heartbeats stopped (the driver's watchdog stops the arm)";

}  // namespace

const char* to_string(GraspState state) { return grasp_state_name(static_cast<int>(state)); }
const char* to_string(GraspActivity activity) {
  return grasp_activity_name(static_cast<int>(activity));
}
const char* to_string(GraspAction action) { return grasp_action_name(static_cast<int>(action)); }
const char* to_string(GraspOutcome outcome) {
  return grasp_outcome_name(static_cast<int>(outcome));
}

const char* to_string(ArmNeed need) {
  switch (need) {
    case ArmNeed::kNone:
      return "none";
    case ArmNeed::kWanted:
      return "wanted";
    case ArmNeed::kSilent:
      return "silent";
  }
  return "unknown";
}

const char* to_string(CommandResult result) {
  return grasp_command_result_name(static_cast<int>(result));
}

const char* to_string(GraspCommand command) {
  switch (command) {
    case GraspCommand::kTrack:
      return "track";
    case GraspCommand::kGrasp:
      return "grasp";
    case GraspCommand::kRelease:
      return "release";
    case GraspCommand::kAbort:
      return "abort";
    case GraspCommand::kHome:
      return "home";
  }
  return "unknown";
}

GraspMachine::GraspMachine(ArmGeometry geometry, GraspSettings settings, int64_t first_sequence)
    : geometry_(std::move(geometry)),
      settings_(std::move(settings)),
      next_sequence_(first_sequence),
      delay_(settings_.default_delay),
      first_sequence_(first_sequence) {}

// ---------------------------------------------------------------------------------------------
// Inputs.

CommandReply GraspMachine::on_command(GraspCommand command, double standoff, int64_t now) {
  update(now);
  const std::string where =
      std::string(" in ") + to_string(status_.state) + " (" + to_string(status_.activity) + ")";
  switch (command) {
    case GraspCommand::kTrack:
      return track(standoff, where);
    case GraspCommand::kGrasp:
      return grasp(where, now);
    case GraspCommand::kRelease:
      return release(where);
    case GraspCommand::kAbort:
      return abort(where);
    case GraspCommand::kHome:
      return home(where);
  }
  return refuse_command(CommandResult::kRefusedUnknownCommand,
                        "unknown command " + std::to_string(static_cast<int>(command)));
}

CommandReply GraspMachine::track(double standoff, const std::string& where) {
  const GraspState state = status_.state;
  const GraspActivity activity = status_.activity;
  if (state != GraspState::kHandOpened || activity == GraspActivity::kGrasping ||
      activity == GraspActivity::kBackingOff) {
    return refuse_command(
        CommandResult::kRefusedState,
        "track refused" + where +
            (state == GraspState::kHandOpened ? "" : ": release the object first"));
  }
  if (standoff != 0) {
    if (!(std::isfinite(standoff) && standoff > 0)) {
      return refuse_command(CommandResult::kRefusedBadArgument,
                            "track: stand-off " + fixed(standoff, 3) +
                                " m refused (must be > 0); kept " + fixed(settings_.standoff, 3) +
                                " m");
    }
    settings_.standoff = standoff;
  }
  status_.activity = GraspActivity::kTracking;
  if (next_ == NextAction::kHome) next_ = NextAction::kNone;
  set_message("");
  return {CommandResult::kAccepted, ""};
}

CommandReply GraspMachine::grasp(const std::string& where, int64_t now) {
  const GraspActivity activity = status_.activity;
  if (status_.state != GraspState::kHandOpened || activity == GraspActivity::kGrasping ||
      activity == GraspActivity::kBackingOff) {
    return refuse_command(CommandResult::kRefusedState, "grasp refused" + where);
  }
  if (!track_fresh(now)) {
    return refuse_command(CommandResult::kRefusedState,
                          "grasp refused: no fresh track of the object");
  }
  status_.state = GraspState::kApproaching;
  status_.activity = GraspActivity::kGrasping;
  grasp_utime_ = now;
  replans_in_grasp_ = 0;
  status_.last_action = GraspAction::kApproachObject;
  status_.outcome = GraspOutcome::kNone;
  if (next_ == NextAction::kHome) next_ = NextAction::kNone;
  if (arm_.gripper != Status::GRIPPER_OPEN) plan(NextAction::kOpen);  // a0, then the approach
  set_message("");
  return {CommandResult::kAccepted, ""};
}

CommandReply GraspMachine::release(const std::string& where) {
  if (status_.state != GraspState::kHandClosed && status_.state != GraspState::kObjectLifted) {
    return refuse_command(CommandResult::kRefusedState,
                          "release ignored" + where + ": the hand holds nothing");
  }
  if (grasp_in_progress()) abort_grasp("released" + where);
  status_.activity = GraspActivity::kIdle;
  judging_ = false;
  if (next_ == NextAction::kLift || next_ == NextAction::kHome) next_ = NextAction::kNone;
  plan(NextAction::kOpen);
  return {CommandResult::kAccepted, ""};
}

CommandReply GraspMachine::abort(const std::string& where) {
  if (grasp_in_progress()) abort_grasp("aborted" + where);
  status_.state = GraspState::kHandOpened;
  status_.activity = GraspActivity::kIdle;
  judging_ = false;
  next_ = NextAction::kStop;  // the STOP opens the hand: no a0, lift, back-off or home after it
  retry_utime_ = 0;           // an operator's abort waits for no back-off
  return {CommandResult::kAccepted, ""};
}

CommandReply GraspMachine::home(const std::string& where) {
  const GraspActivity activity = status_.activity;
  if (activity == GraspActivity::kGrasping || activity == GraspActivity::kBackingOff) {
    return refuse_command(CommandResult::kRefusedState, "home refused" + where + ": abort first");
  }
  // While homing, the HOME is pending, hidden by a stop or a0 (follow_up()), or in flight.
  if (activity == GraspActivity::kHoming) return {CommandResult::kAccepted, ""};
  status_.activity = GraspActivity::kHoming;
  plan(NextAction::kHome);
  set_message("");
  return {CommandResult::kAccepted, ""};
}

CommandReply GraspMachine::refuse_command(CommandResult result, std::string reason) {
  refuse(reason);
  return {result, std::move(reason)};
}

void GraspMachine::on_trajectory(const PredictedPath& path, int64_t source_utime, int64_t now) {
  path_ = path;  // without prediction only its liveness counts (fresh_path())
  path_source_utime_ = source_utime;
  update(now);
}

void GraspMachine::on_measurement(const std::optional<Eigen::Vector3d>& position, int64_t utime) {
  if (position && position->allFinite() && utime >= measured_utime_) {
    measured_ = *position;
    measured_utime_ = utime;
  }
  judge(utime);
}

void GraspMachine::on_arm_status(const ArmView& arm, int64_t now) {
  const bool restarted = have_arm_ && arm.driver_start_utime != arm_.driver_start_utime;
  const bool watchdog = have_arm_ && !arm.watchdog.empty() && arm.watchdog != arm_.watchdog;
  if (!have_arm_) start_from(arm);
  arm_ = arm;
  have_arm_ = true;
  arm_utime_ = now;
  // The old driver may have executed the request in flight: never resend it, compute afresh.
  if (restarted && in_flight_) answered(true, "driver restarted: abandoned ", now);

  // The delay: the driver publishes a new interaction_time once the interaction of its
  // last_executed_sequence is complete.
  if (arm.interaction_time != seen_interaction_time_) {
    seen_interaction_time_ = arm.interaction_time;
    const auto it = motion_commands_.find(arm.last_executed_sequence);
    if (it != motion_commands_.end()) {
      const double sample = arm.interaction_time / std::max(it->second, 1);
      if (it->second > 0 && std::isfinite(sample) && sample > 0 && sample < 10) {
        delay_ = (1 - kDelayWeight) * delay_ + kDelayWeight * sample;
      }
      motion_commands_.erase(it);
    }
  }

  if (in_flight_) {
    const int64_t sequence = in_flight_->sequence;
    if (arm.last_rejected_sequence == sequence) {
      rejected(now);
    } else if (arm.last_executed_sequence == sequence) {
      rejections_ = 0;
      retry_utime_ = 0;
      if (waiting_for_lease_) set_message("");  // the lease is ours again
      waiting_for_lease_ = false;
      answered(false, "", now);
    }
  }
  // The watchdog's STOP replaced a request the driver held: it will not be executed.
  if (watchdog && in_flight_)
    answered(true, "the driver's watchdog stopped the arm: abandoned ", now);
  if (judging_ && !stopped_utime_ && !in_flight_ && !arm.moving) stopped_utime_ = now;
  update(now);
}

// ---------------------------------------------------------------------------------------------
// Requests.

std::optional<ArmRequest> GraspMachine::take_request(int64_t now) {
  std::optional<ArmRequest> r = choose_request(now);
  // Kept whole (cartesian() and aim() fill it in after make()), for a resend.
  if (r && in_flight_ && in_flight_->sequence == r->sequence) in_flight_->request = *r;
  return r;
}

std::optional<ArmRequest> GraspMachine::choose_request(int64_t now) {
  update(now);
  if (!have_arm_ || !arm_.connected) return std::nullopt;
  // At once, even with one in flight or ARM_STATUS silent: a STOP is safe, obeyed from anyone.
  if (next_ == NextAction::kStop && now >= retry_utime_) return send_stop(now);
  if (arm_status_silence(now)) return std::nullopt;
  if (in_flight_) {
    if (std::optional<ArmRequest> r = replan(now)) return r;
    return resend(now);
  }
  if (now < retry_utime_) return std::nullopt;
  switch (next_) {
    case NextAction::kOpen:
      return send_open(now);
    case NextAction::kHome:
      return send_home(now);
    case NextAction::kBackoff:
      return send_backoff(now);
    case NextAction::kLift:
      return send_lift(now);
    case NextAction::kStop:
    case NextAction::kNone:
      break;
  }
  const GraspActivity activity = status_.activity;
  if (activity == GraspActivity::kGrasping && status_.state == GraspState::kApproaching) {
    // A re-plan that came too late left the hand closed: open it before approaching again.
    if (arm_.gripper == Status::GRIPPER_CLOSED) return send_open(now);
    return send_approach(now);
  }
  if (activity == GraspActivity::kTracking && status_.state == GraspState::kHandOpened) {
    return aim(Kind::kTrack, now);
  }
  return std::nullopt;
}

std::optional<ArmRequest> GraspMachine::resend(int64_t now) {
  if (arm_has(in_flight_->sequence)) return std::nullopt;
  if (now - in_flight_->resent_utime < to_us(settings_.resend_after)) return std::nullopt;
  in_flight_->resent_utime = now;
  ++resends_;
  return in_flight_->request;
}

bool GraspMachine::arm_has(int64_t sequence) const {
  return arm_.last_received_sequence == sequence || arm_.last_executed_sequence == sequence ||
         arm_.last_rejected_sequence == sequence;
}

ArmNeed GraspMachine::arm_need(int64_t now) const {
  if (!have_arm_) return ArmNeed::kNone;
  if (arm_status_silence(now)) return ArmNeed::kSilent;
  const GraspActivity activity = status_.activity;
  if (activity == GraspActivity::kTracking && status_.state == GraspState::kHandOpened) {
    return track_fresh(now) ? ArmNeed::kWanted : ArmNeed::kSilent;
  }
  const bool own_motion = arm_.moving && arm_.last_executed_sequence >= first_sequence_ &&
                          arm_.last_executed_sequence < next_sequence_;
  if (in_flight_ || next_ != NextAction::kNone || activity != GraspActivity::kIdle || own_motion) {
    return ArmNeed::kWanted;
  }
  return ArmNeed::kNone;
}

std::optional<double> GraspMachine::arm_status_silence(int64_t now) const {
  if (!have_arm_) return std::nullopt;
  const double silence = static_cast<double>(now - arm_utime_) * 1e-6;
  if (silence <= settings_.arm_status_timeout) return std::nullopt;
  return silence;
}

void GraspMachine::plan(NextAction action) {
  if (action > next_) next_ = action;  // NextAction lists the precedence, lowest first
}

NextAction GraspMachine::follow_up() const {
  switch (status_.activity) {
    case GraspActivity::kBackingOff:
      return NextAction::kBackoff;
    case GraspActivity::kHoming:
      return NextAction::kHome;
    case GraspActivity::kGrasping:
      return status_.state == GraspState::kHandClosed ? NextAction::kLift : NextAction::kNone;
    case GraspActivity::kIdle:
    case GraspActivity::kTracking:
      break;
  }
  return NextAction::kNone;
}

ArmRequest GraspMachine::send_stop(int64_t now) {
  ArmRequest r = make(Kind::kStop, Cmd::MODE_STOP, Cmd::GRIPPER_OPEN, now);
  status_.last_action = GraspAction::kOpenHand;
  status_.target.reset();
  status_.target_utime = 0;
  status_.source_utime = 0;
  next_ = follow_up();
  return r;
}

ArmRequest GraspMachine::send_open(int64_t now) {
  ArmRequest r = make(Kind::kOpenHand, Cmd::MODE_GRIPPER_ONLY, Cmd::GRIPPER_OPEN, now);
  status_.last_action = GraspAction::kOpenHand;
  // The hand held something (release): q0. In q1 (a grasp asked for before the first a0 went
  // out) the approach follows.
  if (status_.state != GraspState::kApproaching) status_.state = GraspState::kHandOpened;
  next_ = follow_up();
  return r;
}

ArmRequest GraspMachine::send_home(int64_t now) {
  next_ = NextAction::kNone;
  ArmRequest r = make(Kind::kHome, Cmd::MODE_HOME, Cmd::GRIPPER_KEEP, now);
  status_.target.reset();
  status_.target_utime = 0;
  status_.source_utime = 0;
  return r;
}

std::optional<ArmRequest> GraspMachine::send_backoff(int64_t now) {
  next_ = NextAction::kNone;
  Eigen::Vector3d up = arm_.tool + Eigen::Vector3d(0, 0, settings_.backoff);
  up.z() = std::min(up.z(), geometry_.workspace.max.z());
  const std::string problem = check_target(up);
  if (!problem.empty()) {
    status_.activity = GraspActivity::kIdle;
    set_message("track lost; back-off refused: " + problem);
    return std::nullopt;
  }
  const Eigen::Vector3d rpy =
      rpy_from_rotation(forward_kinematics(geometry_, arm_.joints).rotation());
  return cartesian(Kind::kBackoff, up, rpy, Cmd::GRIPPER_KEEP, now);
}

std::optional<ArmRequest> GraspMachine::send_lift(int64_t now) {
  next_ = NextAction::kNone;
  Eigen::Vector3d up = approach_position_ + Eigen::Vector3d(0, 0, settings_.lift);
  up.z() = std::min(up.z(), geometry_.workspace.max.z());
  const std::string problem = check_target(up);
  if (!problem.empty()) {
    status_.activity = GraspActivity::kIdle;
    status_.outcome = GraspOutcome::kFailed;
    set_message("lift refused: " + problem);
    return std::nullopt;
  }
  status_.last_action = GraspAction::kLiftObject;
  return cartesian(Kind::kLift, up, approach_rpy_, Cmd::GRIPPER_KEEP, now);
}

std::optional<ArmRequest> GraspMachine::send_approach(int64_t now) {
  std::optional<ArmRequest> r = aim(Kind::kApproach, now);
  if (r && r->gripper == Cmd::GRIPPER_CLOSE) {
    status_.state = GraspState::kGrasping;
    status_.last_action = GraspAction::kCloseHand;
  }
  return r;
}

std::string GraspMachine::replan_reason(int64_t now) const {
  const InFlight& approach = *in_flight_;
  if (approach.kind != Kind::kApproach || status_.state != GraspState::kGrasping ||
      status_.activity != GraspActivity::kGrasping || !settings_.use_prediction) {
    return "";
  }
  if (replans_in_grasp_ >= settings_.max_replans) return "";
  if (now - grasp_utime_ >= to_us(settings_.max_wait)) return "";  // the close on a guess stands
  // Past this the CLOSE may be on the line already.
  if (now - approach.sent_utime >= to_us(delay_ - settings_.replan_margin)) return "";
  int64_t source_utime = 0;
  const std::optional<PredictedPath> path = fresh_path(now, &source_utime);
  if (!path || source_utime <= approach.request.source_utime) return "";
  const int64_t t = approach.request.target_utime;
  const std::optional<Eigen::Vector3d> ball = path->at(t);
  if (!ball) return "";
  // The approach's offset is 0: its tool target is the ball it aimed at.
  const double shift = (*ball - approach.request.position).norm();
  if (shift > settings_.replan_shift) return "the ball at T moved " + fixed(shift * 1e3, 1) + " mm";
  const std::optional<double> sigma = close_sigma(*path, t);
  if (sigma && settings_.confidence * *sigma > settings_.tolerance) {
    return "at T " + fixed(settings_.confidence, 1) + " sigma " +
           fixed(settings_.confidence * *sigma * 1e3, 1) + " mm > " +
           fixed(settings_.tolerance * 1e3, 1) + " mm tolerance";
  }
  return "";
}

std::optional<ArmRequest> GraspMachine::replan(int64_t now) {
  const std::string why = replan_reason(now);
  if (why.empty()) return std::nullopt;
  const int64_t superseded = in_flight_->sequence;
  const GraspState state = status_.state;
  status_.state = GraspState::kApproaching;  // q1's request, now
  std::optional<ArmRequest> r = send_approach(now);
  if (!r) {  // no target now: the approach in flight stands
    status_.state = state;
    return std::nullopt;
  }
  motion_commands_.erase(superseded);  // its interaction may be a motion alone now
  ++replans_;
  ++replans_in_grasp_;
  if (r->gripper != Cmd::GRIPPER_CLOSE) status_.last_action = GraspAction::kApproachObject;
  set_message("re-planned (request " + std::to_string(superseded) + "): " + why +
              (status_.message.empty() ? "" : "; " + status_.message));
  return r;
}

std::optional<ArmRequest> GraspMachine::aim(Kind kind, int64_t now) {
  int64_t source_utime = 0;
  const std::optional<PredictedPath> path = fresh_path(now, &source_utime);
  if (!path) {  // an approach's waiting message is update()'s
    if (kind != Kind::kApproach)
      refuse(kind == Kind::kTrack ? kStaleTrack : "no fresh track of the object");
    return std::nullopt;
  }
  bool approach = kind == Kind::kApproach;
  Interception aim = intercept_for(*path, approach, now);
  std::string note;
  if (approach && aim.ok && !ready_to_close(*path, aim, now, &note)) {
    approach = false;  // above the ball as when tracking (still q1), and approach from there
    kind = Kind::kTrack;
    aim = intercept_for(*path, false, now);
  }
  if (!aim.ok) {
    refuse("target refused: " + aim.error);
    return std::nullopt;
  }
  const std::string problem = check_target(aim.pose.position);
  if (!problem.empty()) {
    refuse("target refused: " + problem);
    return std::nullopt;
  }
  std::optional<ArmRequest> r = cartesian(kind, aim.pose.position, aim.pose.rpy,
                                          approach ? Cmd::GRIPPER_CLOSE : Cmd::GRIPPER_KEEP, now);
  if (!note.empty()) set_message(note);
  r->source_utime = source_utime;
  r->target_utime = aim.arrival_utime;
  status_.target_utime = aim.arrival_utime;
  status_.source_utime = source_utime;
  if (approach) {
    approach_position_ = aim.pose.position;
    approach_rpy_ = aim.pose.rpy;
  }
  return r;
}

Interception GraspMachine::intercept_for(const PredictedPath& path, bool approach,
                                         int64_t now) const {
  const Eigen::Vector3d offset(0, 0, approach ? 0.0 : settings_.standoff);
  return intercept(geometry_, path, arm_.joints, now, delay_, approach ? delay_ : 0.0, offset,
                   settings_.speed, settings_.interception);
}

bool GraspMachine::ready_to_close(const PredictedPath& path, const Interception& aim, int64_t now,
                                  std::string* note) const {
  note->clear();
  // The CLOSE travelling with the approach executes one delay after the motion starts: when the
  // motion takes longer, the hand would close short of the ball. Close in first.
  if (motion_time(geometry_, arm_.joints, aim.joints, settings_.speed) > delay_) return false;
  const std::optional<double> sigma = close_sigma(path, aim.arrival_utime);
  if (!sigma) return true;  // no estimate: the baseline's hold path
  const double bound = settings_.confidence * *sigma;
  const std::string sure = fixed(settings_.confidence, 1) + " sigma " + fixed(bound * 1e3, 1) +
                           " mm " + (bound <= settings_.tolerance ? "<=" : ">") + " " +
                           fixed(settings_.tolerance * 1e3, 1) + " mm tolerance";
  if (bound <= settings_.tolerance) {
    *note = "closing: " + sure;
    return true;
  }
  const double left = settings_.max_wait - 1e-6 * static_cast<double>(now - grasp_utime_);
  if (left <= 0) {
    *note = "closing on a guess after " + fixed(settings_.max_wait, 1) + " s: " + sure;
    return true;
  }
  *note = "waiting to close: " + sure + " (" + fixed(left, 1) + " s left)";
  return false;
}

std::optional<double> GraspMachine::close_sigma(const PredictedPath& path, int64_t t) const {
  const std::optional<Eigen::Vector3d> sigma = path.sigma_at(t);
  if (!sigma) return std::nullopt;
  double speed = 0;  // |p'(t)|, a central difference over one period where the path has it
  const int64_t half = path.period_us / 2;
  const auto before = path.at(t - half), after = path.at(t + half);
  if (before && after && half > 0) speed = (*after - *before).norm() / (2e-6 * half);
  const double timing = speed * settings_.timing_sigma;
  return std::sqrt(sigma->squaredNorm() + settings_.arm_sigma * settings_.arm_sigma +
                   timing * timing);
}

std::optional<ArmRequest> GraspMachine::cartesian(Kind kind, const Eigen::Vector3d& position,
                                                  const Eigen::Vector3d& rpy, int8_t gripper,
                                                  int64_t now) {
  ArmRequest r = make(kind, Cmd::MODE_CARTESIAN, gripper, now);
  r.position = position;
  r.rpy = rpy;
  status_.target = position;
  status_.target_utime = 0;
  status_.source_utime = 0;
  return r;
}

ArmRequest GraspMachine::make(Kind kind, int8_t mode, int8_t gripper, int64_t now) {
  ArmRequest r;
  r.sequence = next_sequence_++;
  r.mode = mode;
  r.gripper = gripper;
  r.speed = settings_.speed;
  in_flight_ = InFlight{r.sequence, kind, now, now, r};
  motion_commands_[r.sequence] = motion_commands(mode, gripper);
  while (motion_commands_.size() > kRememberedRequests) {
    motion_commands_.erase(motion_commands_.begin());
  }
  if (message_is_refusal_ && !waiting_for_lease_) set_message("");
  return r;
}

// ---------------------------------------------------------------------------------------------
// Answers, time and the track.

void GraspMachine::start_from(const ArmView& arm) {
  // An abort before the first status: the STOP opens the hand, q0 stands.
  if (arm.gripper != Status::GRIPPER_CLOSED || next_ == NextAction::kStop) return;
  status_.state = GraspState::kHandClosed;
  if (next_ == NextAction::kOpen) next_ = NextAction::kNone;  // a0 only when asked
  const GraspActivity activity = status_.activity;
  if (activity == GraspActivity::kTracking || activity == GraspActivity::kGrasping) {
    status_.activity = GraspActivity::kIdle;
    refuse(std::string("the gripper is reported closed: q3 hand closed, ") +
           (activity == GraspActivity::kTracking ? "track" : "grasp") +
           " cancelled (release first)");
  }
}

void GraspMachine::rejected(int64_t now) {
  ++rejections_;
  const double wait = kRetryFirst * std::ldexp(1.0, std::min(rejections_, 30) - 1);
  retry_utime_ = now + to_us(std::min(wait, kRetryLongest));
  const std::string lease = lease_holder_note(arm_.rejection_reason);
  waiting_for_lease_ = !lease.empty();
  answered(true, "the arm rejected ", now);
  if (waiting_for_lease_) refuse("waiting: " + lease + "; " + status_.message);
}

void GraspMachine::answered(bool failed, const std::string& failure, int64_t now) {
  const InFlight done = *in_flight_;
  in_flight_.reset();
  const std::string request = " (request " + std::to_string(done.sequence) + ")";
  switch (done.kind) {
    case Kind::kOpenHand:
      if (failed) {
        plan(NextAction::kOpen);
        refuse(failure + "a0 open hand" + request);
      }
      return;
    case Kind::kStop:
      if (failed) {
        plan(NextAction::kStop);
        refuse(failure + "the stop" + request);
      }
      return;
    case Kind::kHome:
      home_answered(failed, failure, request);
      return;
    case Kind::kTrack:
      if (failed) refuse(failure + "the tracking target" + request);
      return;
    case Kind::kApproach:
      approach_answered(failed, failure, request);
      return;
    case Kind::kLift:
      lift_answered(failed, failure, request, now);
      return;
    case Kind::kBackoff:
      backoff_answered(failed, failure, request);
      return;
  }
}

void GraspMachine::home_answered(bool failed, const std::string& failure,
                                 const std::string& request) {
  if (status_.activity == GraspActivity::kHoming && next_ != NextAction::kHome) {
    status_.activity = GraspActivity::kIdle;
  }
  if (failed) set_message(failure + "home" + request);
}

void GraspMachine::approach_answered(bool failed, const std::string& failure,
                                     const std::string& request) {
  if (status_.state != GraspState::kGrasping || status_.activity != GraspActivity::kGrasping) {
    return;
  }
  if (failed) {  // back to q1: a1 again
    status_.state = GraspState::kApproaching;
    status_.last_action = GraspAction::kApproachObject;
    refuse(failure + "the approach" + request + "; trying again");
  } else {  // q2 -> q3: the hand closed on the ball; a3 next
    status_.state = GraspState::kHandClosed;
    plan(NextAction::kLift);
  }
}

void GraspMachine::lift_answered(bool failed, const std::string& failure,
                                 const std::string& request, int64_t now) {
  if (status_.state != GraspState::kHandClosed || status_.activity != GraspActivity::kGrasping) {
    return;
  }
  if (failed) {
    status_.activity = GraspActivity::kIdle;
    status_.outcome = GraspOutcome::kFailed;
    set_message(failure + "the lift" + request);
  } else {  // q3 -> q4: lifted; judge() decides the outcome from here
    status_.state = GraspState::kObjectLifted;
    judging_ = true;
    nearest_ = std::numeric_limits<double>::infinity();
    lifted_utime_ = now;
    stopped_utime_.reset();
  }
}

void GraspMachine::backoff_answered(bool failed, const std::string& failure,
                                    const std::string& request) {
  if (status_.activity == GraspActivity::kBackingOff) {
    status_.activity = GraspActivity::kIdle;
    if (failed) set_message("track lost; " + failure + "the back-off" + request);
  }
}

void GraspMachine::update(int64_t now) {
  if (in_flight_) {
    const double limit = std::max(kAnswerTimeout, 8 * delay_);
    if (now - in_flight_->sent_utime > to_us(limit)) answered(true, "the arm did not answer ", now);
  }
  note_stale_track(now);
  if (status_.state == GraspState::kApproaching && status_.activity == GraspActivity::kGrasping &&
      !track_fresh(now)) {
    // Waiting to close (a panel or the gripper hides the ball longer than the predictor coasts):
    // the arm holds where it is until the track returns, up to max_wait after the command.
    const double left = settings_.max_wait - 1e-6 * static_cast<double>(now - grasp_utime_);
    if (left > 0) {
      refuse("waiting to close: no fresh track of the object (" + fixed(left, 1) + " s left)");
      judge(now);
      return;
    }
    status_.state = GraspState::kHandOpened;
    status_.activity = GraspActivity::kBackingOff;
    status_.outcome = GraspOutcome::kFailed;
    set_message("track lost");
    plan(NextAction::kBackoff);
  }
  judge(now);
}

void GraspMachine::note_stale_track(int64_t now) {
  const bool tracking =
      status_.activity == GraspActivity::kTracking && status_.state == GraspState::kHandOpened;
  const bool stale = tracking && !track_fresh(now);
  if (stale && status_.message != kStaleTrack && !waiting_for_lease_) {
    refuse(kStaleTrack);
  } else if (!stale && status_.message == kStaleTrack) {
    set_message("");
  }
}

void GraspMachine::judge(int64_t now) {
  if (!judging_) return;
  // From when a measurement says where the ball is with the arm at rest; over a window, since one
  // sighting can be another red thing while the gripper or a panel hides the ball.
  const int64_t rest = stopped_utime_ ? *stopped_utime_ : lifted_utime_ + to_us(kSettleTimeout);
  if (now < rest) return;
  if (measured_ && measured_utime_ >= rest) {
    nearest_ = std::min(nearest_, (*measured_ - arm_.tool).norm());
  }
  const std::string limit = " (limit " + fixed(settings_.success_distance, 3) + " m)";
  if (nearest_ <= settings_.success_distance) {
    status_.outcome = GraspOutcome::kSuccess;
    set_message("object held: ball " + fixed(nearest_, 3) + " m from the tool" + limit);
  } else if (now > rest + to_us(settings_.judge_time)) {
    status_.outcome = GraspOutcome::kFailed;
    set_message(std::isfinite(nearest_) ? "object not held: ball " + fixed(nearest_, 3) +
                                              " m from the tool at the nearest" + limit
                                        : "ball not seen after the lift");
  } else {
    return;
  }
  judging_ = false;
  status_.activity = GraspActivity::kIdle;
}

bool GraspMachine::track_fresh(int64_t now) const {
  int64_t source_utime = 0;
  return fresh_path(now, &source_utime).has_value();
}

std::optional<PredictedPath> GraspMachine::fresh_path(int64_t now, int64_t* source_utime) const {
  const int64_t oldest = now - to_us(settings_.max_trajectory_age);
  if (settings_.use_prediction) {
    if (!path_ || path_->lost || path_->points.empty() || path_->utime < oldest) {
      return std::nullopt;
    }
    *source_utime = path_source_utime_;
    return path_;
  }
  // Without prediction: the last measured position, held. The track is alive while the
  // measurement is fresh, or while the predictor still tracks the ball (through an occlusion): the
  // baseline then aims where the ball was last seen, as a system without a predictor would.
  if (!measured_) return std::nullopt;
  const bool tracked = path_ && !path_->lost && path_->utime >= oldest;
  if (measured_utime_ < oldest && !tracked) return std::nullopt;
  *source_utime = measured_utime_;
  return PredictedPath::hold(*measured_, std::max(now, measured_utime_));
}

// ---------------------------------------------------------------------------------------------
// Small helpers.

std::string GraspMachine::check_target(const Eigen::Vector3d& target) const {
  if (!target.allFinite()) return "target is not finite";
  const double floor = settings_.interception.table_z + settings_.interception.table_margin;
  if (!(target.z() >= floor)) {
    return "target below the table plus margin (z = " + fixed(target.z(), 3) + " m < " +
           fixed(floor, 3) + " m)";
  }
  if (!geometry_.workspace.contains(target)) {
    return "target outside the workspace (" + fixed(target.x(), 3) + ", " + fixed(target.y(), 3) +
           ", " + fixed(target.z(), 3) + ") m";
  }
  return "";
}

bool GraspMachine::grasp_in_progress() const {
  return status_.activity == GraspActivity::kGrasping;
}

void GraspMachine::abort_grasp(const std::string& why) {
  status_.outcome = GraspOutcome::kAborted;
  set_message(why);
}

void GraspMachine::refuse(std::string message) {
  status_.message = std::move(message);
  message_is_refusal_ = true;
}

void GraspMachine::set_message(std::string message) {
  status_.message = std::move(message);
  message_is_refusal_ = false;
}

}  // namespace sg::grasp
