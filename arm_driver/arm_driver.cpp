#include "arm_driver/arm_driver.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace sg::arm {
namespace {

using Cmd = stereograsp::arm_cmd_t;
using Status = stereograsp::arm_status_t;
/// Wraps the line and adds up the time spent inside it (waiting for bytes, writing them): the
/// rest of an interaction is the driver's own overhead.
class TimedStream final : public ByteStream {
 public:
  TimedStream(std::unique_ptr<ByteStream> inner, Clock& clock)
      : inner_(std::move(inner)), clock_(clock) {}
  void write(std::span<const uint8_t> bytes) override {
    const double start = clock_.now();
    inner_->write(bytes);
    inside_ += clock_.now() - start;
  }
  std::optional<uint8_t> read_byte(std::chrono::microseconds timeout) override {
    const double start = clock_.now();
    auto byte = inner_->read_byte(timeout);
    inside_ += clock_.now() - start;
    return byte;
  }
  void discard_input() override { inner_->discard_input(); }
  double inside() const { return inside_; }

 private:
  std::unique_ptr<ByteStream> inner_;
  Clock& clock_;
  double inside_ = 0;
};

Joints to_joints(const rapl::JointArray& q) { return Eigen::Map<const Joints>(q.data()); }

rapl::JointArray to_array(const Joints& q) {
  rapl::JointArray out;
  for (int i = 0; i < 6; ++i) out[i] = q[i];
  return out;
}

}  // namespace

void set_joints(const ArmGeometry& geometry, const Joints& q, Status& status) {
  for (int i = 0; i < 6; ++i) status.joints[i] = q[i];
  const Eigen::Isometry3d tool = forward_kinematics(geometry, q);
  const Eigen::Vector3d rpy = rpy_from_rotation(tool.linear());
  for (int i = 0; i < 3; ++i) {
    status.tool_position[i] = tool.translation()[i];
    status.tool_orientation[i] = rpy[i];
  }
}

ArmDriver::ArmDriver(ArmGeometry geometry, DriverSettings settings, DeviceOpener open_device,
                     Clock& clock)
    : validator_(std::move(geometry)),
      lease_(settings.commander_timeout),
      settings_(settings),
      open_device_(std::move(open_device)),
      clock_(clock) {
  status_.state = Status::STATE_DISCONNECTED;
  status_.gripper = Status::GRIPPER_UNKNOWN;
  status_.last_received_sequence = -1;
  status_.last_executed_sequence = -1;
  status_.last_rejected_sequence = -1;
  status_.speed = 0;
  status_.driver_start_utime = settings.start_utime != 0 ? settings.start_utime : clock.utime();
  set_joints(validator_.geometry(), current_, status_);
}

template <class F>
void ArmDriver::update(F&& change) {
  std::lock_guard lock(mutex_);
  change(status_);
  ++version_;
}

Submission ArmDriver::submit(const Cmd& command) {
  std::lock_guard lock(mutex_);
  const double t = clock_.now();
  watchdog(t);  // a holder silent beyond the timeout is gone, whoever speaks now
  const LeaseDecision lease = lease_.offer(command.sender, command.mode, command.take_over, t);
  if (lease.verdict == LeaseVerdict::kRefused) return refuse_by_lease(command, lease.reason);
  if (lease.changed) note_lease_change(command.sender, lease);
  if (lease.verdict == LeaseVerdict::kRenewed || lease.verdict == LeaseVerdict::kReleased) {
    return {Submission::kLease, ""};
  }
  Submission result = queue(command);
  clock_.notify();
  return result;
}

void ArmDriver::note_lease_change(const std::string& sender, const LeaseDecision& lease) {
  if (!lease.taken_from.empty()) {
    spdlog::warn("'{}' takes the arm over from '{}'", sender, lease.taken_from);
  } else if (lease_.held()) {
    spdlog::info("'{}' commands the arm", sender);
  } else {
    spdlog::info("'{}' releases the arm", sender);
  }
  status_.commander = lease_.holder();
  if (lease_.held()) status_.last_received_sequence = validator_.last_sequence(lease_.holder());
  ++version_;
}

Submission ArmDriver::refuse_by_lease(const Cmd& command, const std::string& why) {
  spdlog::debug("refused command {} (mode {}) from '{}': {}", command.sequence, int{command.mode},
                command.sender, why);
  if (command.mode != Cmd::MODE_HEARTBEAT && command.mode != Cmd::MODE_RELEASE) {
    status_.last_rejected_sequence = command.sequence;  // sg-arm-ctl reads its refusal here
    status_.rejection_reason = why;
    ++version_;
  }
  return {Submission::kRefused, why};
}

Submission ArmDriver::queue(const Cmd& command) {
  const Joints reference =
      pending_ && pending_->moves_arm() ? pending_->joints : commanded_.value_or(current_);
  ValidationResult result = validator_.validate(command, reference);
  if (command.sender == lease_.holder())
    status_.last_received_sequence = validator_.last_sequence(command.sender);
  ++version_;  // a duplicate too: the status goes out again, for a sender that missed it
  if (result.duplicate) {
    spdlog::debug("{}: ignored", result.reason);
    return {Submission::kDuplicate, ""};
  }
  if (!result.target) {
    status_.last_rejected_sequence = command.sequence;
    status_.rejection_reason = result.reason;
    if (uint64_t held_back = 0; log_limit_.allow("rejected", clock_.now(), held_back)) {
      spdlog::warn("rejected command {} from '{}': {}{}", command.sequence, command.sender,
                   result.reason,
                   held_back ? fmt::format(" ({} more rejections not logged)", held_back) : "");
    }
    return {Submission::kRejected, result.reason};
  }
  if (pending_) spdlog::debug("command {} replaces {}", command.sequence, pending_->sequence);
  pending_ = std::move(*result.target);
  return {Submission::kQueued, ""};
}

void ArmDriver::watchdog(double t) {
  if (!lease_.expired(t)) return;
  const double silence = t - lease_.heard();
  const std::string holder = lease_.expire(t);
  status_.commander.clear();
  ++version_;
  const bool pending_motion = pending_ && pending_->mode != Cmd::MODE_STOP;
  if (status_.state != Status::STATE_MOVING && !pending_motion) {
    spdlog::info("'{}' silent for {:.2f} s: the lease is free", holder, silence);
    return;
  }
  ArmTarget stop;
  stop.mode = Cmd::MODE_STOP;
  stop.gripper = Cmd::GRIPPER_KEEP;  // never open the hand unasked
  stop.sender = "watchdog";
  stop.sequence = -1;
  stop.internal = true;
  if (!pending_ || pending_->mode != Cmd::MODE_STOP) pending_ = std::move(stop);
  status_.watchdog = fmt::format("stopped: '{}' silent for {:.2f} s", holder, silence);
  status_.error = status_.watchdog;
  spdlog::warn("watchdog: {}", status_.watchdog);
  clock_.notify();
}

void ArmDriver::refuse(const Cmd& command, const std::string& why) {
  std::lock_guard lock(mutex_);
  status_.last_rejected_sequence = command.sequence;
  status_.rejection_reason = why;
  spdlog::debug("refused command {} from '{}': {}", command.sequence, command.sender, why);
  ++version_;
}

std::pair<Status, uint64_t> ArmDriver::status() const {
  std::lock_guard lock(mutex_);
  return {status_, version_};
}

double ArmDriver::last_overhead() const {
  std::lock_guard lock(mutex_);
  return overhead_;
}

uint64_t ArmDriver::gripper_actions_dropped() const {
  std::lock_guard lock(mutex_);
  return gripper_actions_dropped_;
}

bool ArmDriver::connect(std::stop_token stop) {
  double wait = settings_.reconnect_min;
  while (!stop.stop_requested()) {
    try {
      stream_ = std::make_unique<TimedStream>(open_device_(), clock_);
      link_ = std::make_unique<C550Link>(*stream_, settings_.slave, settings_.timing, clock_);
      link_->open_session();
      speed_percent_ = -1;
      read_joints();
      update([](Status& s) {
        s.state = Status::STATE_IDLE;
        s.error.clear();
      });
      spdlog::info("connected: host session open");
      return true;
    } catch (const std::exception& e) {
      link_.reset();
      stream_.reset();
      update([&](Status& s) {
        s.state = Status::STATE_DISCONNECTED;
        s.error = e.what();
      });
      spdlog::warn("cannot connect ({}); again in {:.1f} s", e.what(), wait);
      std::unique_lock lock(mutex_);
      watchdog(clock_.now());
      clock_.wait_until(lock, std::min(clock_.now() + wait, lease_.deadline()),
                        [] { return false; }, stop);
      watchdog(clock_.now());
      wait = std::min(wait * 2, settings_.reconnect_max);
    }
  }
  return false;
}

void ArmDriver::disconnect(const std::string& why) {
  spdlog::error("line lost: {}", why);
  link_.reset();
  stream_.reset();
  update([&](Status& s) {
    s.state = Status::STATE_DISCONNECTED;
    s.error = why;
  });
}

void ArmDriver::read_joints() {
  const Joints q = to_joints(link_->read_joints());
  update([&](Status& s) {
    // Moving: not yet at the joint target sent, or still changing since the last read (a HOME,
    // whose target is the controller's ready pose, has no joint target here).
    const bool changing =
        have_read_ && (q - current_).cwiseAbs().maxCoeff() > settings_.arrived_tolerance;
    current_ = q;
    have_read_ = true;
    set_joints(validator_.geometry(), q, s);
    const bool moving =
        changing ||
        (commanded_ && (q - *commanded_).cwiseAbs().maxCoeff() > settings_.arrived_tolerance);
    if (s.state != Status::STATE_ERROR)
      s.state = moving ? Status::STATE_MOVING : Status::STATE_IDLE;
    if (!moving) s.source_utime = 0;
  });
}

void ArmDriver::act(ArmTarget& target) {
  const auto& timing = settings_.timing;
  if (target.mode == Cmd::MODE_STOP) {
    link_->command("ABORT", timing.reply_timeout);  // then the gripper, if asked (abort: open)
  } else if (target.moves_arm()) {
    link_->command(rapl::move_joints(to_array(target.joints)), timing.motion_reply);
  } else if (target.mode == Cmd::MODE_HOME) {
    link_->command("READY", timing.motion_reply);
  }
  motion_done_ = true;
  if (target.gripper == Cmd::GRIPPER_KEEP) return;
  if (superseded(target)) {
    target.gripper = Cmd::GRIPPER_KEEP;  // executed as a motion alone
    return;
  }
  link_->command(target.gripper == Cmd::GRIPPER_OPEN ? "OPEN" : "CLOSE", timing.motion_reply);
}

bool ArmDriver::superseded(const ArmTarget& target) {
  if (target.mode == Cmd::MODE_STOP || target.mode == Cmd::MODE_GRIPPER_ONLY) return false;
  std::lock_guard lock(mutex_);
  if (!pending_) return false;
  ++gripper_actions_dropped_;
  spdlog::info("command {}: its {} not sent, command {} waits (latest wins)", target.sequence,
               target.gripper == Cmd::GRIPPER_OPEN ? "OPEN" : "CLOSE",
               pending_->internal ? std::string("STOP (watchdog)")
                                  : std::to_string(pending_->sequence));
  return true;
}

void ArmDriver::send_speed(const ArmTarget& target) {
  const double speed = std::min(target.speed, settings_.max_speed);
  const int percent = std::clamp(static_cast<int>(std::lround(speed * 100)), 1, 100);
  if (target.mode != Cmd::MODE_STOP && percent != speed_percent_) {
    link_->command(rapl::speed(percent), settings_.timing.reply_timeout);
    speed_percent_ = percent;
  }
}

void ArmDriver::requeue_rest(ArmTarget target) {
  // A motion delivered and a gripper action not: only the gripper action is tried again.
  if (motion_done_ && target.gripper != Cmd::GRIPPER_KEEP) {
    if (target.moves_arm()) update([&](Status&) { commanded_ = target.joints; });
    target.mode = Cmd::MODE_GRIPPER_ONLY;
  }
  requeue(std::move(target));
}

void ArmDriver::record_executed(const ArmTarget& target) {
  attempts_ = 0;
  update([&](Status& s) {
    if (!target.internal) s.last_executed_sequence = target.sequence;
    s.speed = speed_percent_ / 100.0;
    if (target.mode == Cmd::MODE_STOP || target.mode == Cmd::MODE_HOME) commanded_.reset();
    if (target.moves_arm()) commanded_ = target.joints;
    if (target.gripper == Cmd::GRIPPER_OPEN) s.gripper = Status::GRIPPER_OPEN;
    if (target.gripper == Cmd::GRIPPER_CLOSE) s.gripper = Status::GRIPPER_CLOSED;
    if (s.state == Status::STATE_ERROR) s.state = Status::STATE_MOVING;
    if (!target.internal) s.error.clear();  // the watchdog's stop leaves its reason standing
  });
}

void ArmDriver::record_refusal(const ArmTarget& target, const std::string& why) {
  update([&](Status& s) {
    s.error = "controller: " + why;
    s.state = Status::STATE_ERROR;
    if (target.internal) return;
    s.last_executed_sequence = target.sequence;  // delivered: it ran, and the controller refused
    s.last_rejected_sequence = target.sequence;
    s.rejection_reason = s.error;
  });
}

void ArmDriver::execute(ArmTarget target) {
  const double start = clock_.now();
  const double inside_before = static_cast<TimedStream&>(*stream_).inside();
  update([&](Status& s) {
    s.state = Status::STATE_MOVING;
    s.source_utime = target.source_utime;
  });
  // The command counts as executed once the action's CR is out; until the SPEED before it is
  // through, link_->delivered() tells about the SPEED, not the action.
  bool speed_done = false;
  motion_done_ = false;
  const auto reached_controller = [&] { return speed_done && link_->delivered(); };
  try {
    send_speed(target);
    speed_done = true;
    act(target);
  } catch (const ControllerError& e) {
    record_refusal(target, e.what());
    read_joints();
    return;
  } catch (const LinkError& e) {
    if (!reached_controller()) {
      requeue_rest(std::move(target));
      throw;
    }
    spdlog::warn("command {}: {} (it reached the controller; not sent again)", target.sequence,
                 e.what());
  } catch (const LinkDown&) {
    if (!reached_controller()) {
      requeue_rest(std::move(target));
    } else {
      record_executed(target);  // it reached the controller before the line went: not sent again
    }
    throw;
  }
  record_executed(target);
  read_joints();
  const double total = clock_.now() - start;
  const double inside = static_cast<TimedStream&>(*stream_).inside() - inside_before;
  update([&](Status& s) {
    s.interaction_time = total;
    overhead_ = total - inside;
  });
}

void ArmDriver::requeue(ArmTarget target) {
  std::lock_guard lock(mutex_);
  if (pending_) return;  // a newer command is waiting: latest wins
  if (++attempts_ >= settings_.max_attempts) {
    const std::string why = "not delivered after " + std::to_string(attempts_) + " attempts";
    if (target.internal) {
      status_.error = "watchdog stop " + why;
    } else {
      status_.last_rejected_sequence = target.sequence;
      status_.rejection_reason = why;
    }
    ++version_;
    attempts_ = 0;
    return;
  }
  pending_ = std::move(target);
}

std::optional<ArmTarget> ArmDriver::wait_for_work(std::stop_token stop) {
  std::unique_lock lock(mutex_);
  watchdog(clock_.now());  // first: a motion its commander abandoned must not start
  const bool moving = status_.state == Status::STATE_MOVING;
  const double poll = moving ? settings_.moving_poll : settings_.idle_poll;
  // Wake when the commander's lease runs out too: the watchdog acts on time.
  const double deadline = std::min(clock_.now() + poll, lease_.deadline());
  clock_.wait_until(lock, deadline, [&] { return pending_.has_value(); }, stop);
  watchdog(clock_.now());
  std::optional<ArmTarget> target = std::move(pending_);
  pending_.reset();
  return target;
}

void ArmDriver::run(std::stop_token stop) {
  while (!stop.stop_requested()) {
    if (!link_ && !connect(stop)) return;
    try {
      if (std::optional<ArmTarget> target = wait_for_work(stop)) {
        execute(std::move(*target));
      } else if (!stop.stop_requested()) {
        read_joints();
      }
    } catch (const LinkDown& e) {
      disconnect(e.what());
    } catch (const LinkError& e) {
      spdlog::warn("{}", e.what());
      update([&](Status& s) { s.error = e.what(); });
    }
  }
}

}  // namespace sg::arm
