#include "arm_driver/commander_lease.hpp"

#include <cstdio>
#include <stdexcept>

#include "stereograsp/arm_cmd_t.hpp"

namespace sg::arm {
namespace {

using Cmd = stereograsp::arm_cmd_t;

LeaseDecision decision(LeaseVerdict verdict, bool changed = false) {
  LeaseDecision d;
  d.verdict = verdict;
  d.changed = changed;
  return d;
}

}  // namespace

CommanderLease::CommanderLease(double timeout) : timeout_(timeout) {
  if (!(timeout > 0)) throw std::invalid_argument("commander timeout must be > 0 s");
}

void CommanderLease::hold(const std::string& sender, double t) {
  holder_ = sender;
  heard_ = t;
  deadline_ = t + timeout_;
}

std::string CommanderLease::expire(double t) {
  if (!expired(t)) return "";
  std::string lost = std::move(holder_);
  holder_.clear();
  return lost;
}

LeaseDecision CommanderLease::offer(const std::string& sender, int8_t mode, bool take_over,
                                    double t) {
  const bool mine = held() && holder_ == sender;
  const bool open = !held() || expired(t);  // free, or its holder fell silent
  if (mode == Cmd::MODE_STOP) {
    if (mine) hold(sender, t);
    return decision(LeaseVerdict::kStop);
  }
  if (mode == Cmd::MODE_RELEASE) {
    if (mine || open) {
      const bool changed = held();
      holder_.clear();
      return decision(LeaseVerdict::kReleased, changed);
    }
  } else if (mine || open || take_over) {
    LeaseDecision d = decision(
        mode == Cmd::MODE_HEARTBEAT ? LeaseVerdict::kRenewed : LeaseVerdict::kCommand, !mine);
    if (!mine && !open) d.taken_from = holder_;
    hold(sender, t);
    return d;
  }
  char text[64];
  std::snprintf(text, sizeof text, "%.1f", t - heard_);
  LeaseDecision refused = decision(LeaseVerdict::kRefused);
  refused.reason = "arm commanded by '" + holder_ + "' (heard " + text +
                   " s ago); sg-arm-ctl --take-over takes it";
  return refused;
}

}  // namespace sg::arm
