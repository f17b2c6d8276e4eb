#include "arm_driver/arm_commander.hpp"

#include <spdlog/spdlog.h>

#include "common/clock.hpp"
#include "common/shutdown.hpp"

namespace sg::arm {
namespace {

using Cmd = stereograsp::arm_cmd_t;
using Status = stereograsp::arm_status_t;

CommandReport report(CommandReport::Result result, std::string reason = "") {
  return {result, std::move(reason)};
}

}  // namespace

ArmCommander::ArmCommander(Bus& bus, auth::LabAccess& signer, double heartbeat_period)
    : bus_(bus), signer_(signer), period_(heartbeat_period) {
  bus_.subscribe<Status>("ARM_STATUS", [state = state_](const Status& s, const ReceiveInfo&) {
    state->status = s;
    ++state->statuses;
  });
}

ArmCommander::~ArmCommander() {
  try {
    release();
  } catch (const std::exception& e) {
    spdlog::warn("could not release the arm: {}", e.what());
  }
}

void ArmCommander::publish(Cmd command) {
  command.utime = now_utime();
  signer_.sign("ARM_COMMAND", command);
  name_ = command.sender;
  bus_.publish("ARM_COMMAND", command);
  last_sent_ = std::chrono::steady_clock::now();
}

Cmd ArmCommander::bare(int8_t mode, int64_t sequence) const {
  Cmd c{};
  c.sequence = sequence;
  c.mode = mode;
  c.gripper = Cmd::GRIPPER_KEEP;
  c.speed = 0.5;
  return c;
}

void ArmCommander::send(Cmd command) {
  sequence_ = command.sequence;
  if (command.mode != Cmd::MODE_STOP) holding_ = true;
  publish(std::move(command));
}

void ArmCommander::tick() {
  if (holding_ && std::chrono::steady_clock::now() - last_sent_ >= period_)
    publish(bare(Cmd::MODE_HEARTBEAT, sequence_));
}

void ArmCommander::stop() {
  sequence_ = std::max(sequence_ + 1, now_utime());
  publish(bare(Cmd::MODE_STOP, sequence_));
}

void ArmCommander::release() {
  if (!holding_) return;
  holding_ = false;
  publish(bare(Cmd::MODE_RELEASE, sequence_));
}

CommandReport ArmCommander::judge(int64_t sequence, bool needs_rest) const {
  const Status& s = state_->status;
  if (s.last_rejected_sequence == sequence)
    return report(CommandReport::kRejected, s.rejection_reason);
  if (s.last_executed_sequence < sequence) return report(CommandReport::kTimedOut);
  if (needs_rest && !s.commander.empty() && s.commander != name_)
    return report(CommandReport::kTakenOver, "'" + s.commander + "' took the arm over");
  const bool at_rest = s.state == Status::STATE_IDLE || s.state == Status::STATE_ERROR;
  return report(!needs_rest || at_rest ? CommandReport::kExecuted : CommandReport::kTimedOut);
}

CommandReport ArmCommander::execute(Cmd command, double timeout) {
  const int64_t sequence = command.sequence;
  const bool needs_rest = command.mode != Cmd::MODE_STOP;
  const uint64_t before = state_->statuses;
  send(std::move(command));
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  CommandReport r = report(CommandReport::kTimedOut);
  while (std::chrono::steady_clock::now() < give_up) {
    if (shutdown_requested()) {
      if (needs_rest) stop();
      release();
      return report(CommandReport::kInterrupted, "interrupted: the arm was sent STOP");
    }
    bus_.handle(std::chrono::milliseconds(20));
    tick();
    if (state_->statuses == before) continue;  // nothing heard since the command went out
    r = judge(sequence, needs_rest);
    if (r.result != CommandReport::kTimedOut) break;
  }
  if (r.result == CommandReport::kTimedOut) {
    const Status& s = state_->status;
    r.reason = "command #" + std::to_string(sequence) + " not reported " +
               (s.last_executed_sequence >= sequence ? "at rest" : "executed") + " within " +
               std::to_string(timeout) + " s" + (s.watchdog.empty() ? "" : " (" + s.watchdog + ")");
  }
  if (state_->status.commander == name_) {
    release();
  } else {
    holding_ = false;  // refused or taken over: not ours to release
  }
  return r;
}

}  // namespace sg::arm
