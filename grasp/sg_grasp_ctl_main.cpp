// sg-grasp-ctl: the operator's side of sg-grasp. Sends one GRASP_COMMAND and waits for the
// GRASP_STATUS that answers it (command_sequence = its sequence; command_result accepted or
// refused), or, with --wait, until the grasp (or release, or homing) is over; `status` prints the
// machine's state. Exit status: 0 done, 3 the grasp failed (--wait), 4 refused (also when not
// signed with sg-grasp's lab key), 2 no lab key (--key, default $SG_LAB_KEY or
// ~/.config/stereograsp/lab.key; docs/security.md), 1 other errors.
//
//   sg-grasp-ctl track [--standoff 0.10]      # follow the ball, the gripper above it
//   sg-grasp-ctl grasp --wait                 # q1 approach, q2 grasp, q3 closed, q4 lifted
//   sg-grasp-ctl release | abort | home
//   sg-grasp-ctl status [--follow]

#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>

#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/grasp_names.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "stereograsp/grasp_command_t.hpp"
#include "stereograsp/grasp_status_t.hpp"

namespace {

using Cmd = stereograsp::grasp_command_t;
using Status = stereograsp::grasp_status_t;

void print(const Status& s) {
  std::printf("%-17s %-12s outcome %-8s", sg::grasp_state_name(s.state),
              sg::grasp_activity_name(s.activity), sg::grasp_outcome_name(s.outcome));
  if (std::isfinite(s.target[0])) {
    std::printf(" target (%.3f, %.3f, %.3f) m", s.target[0], s.target[1], s.target[2]);
  }
  if (!s.message.empty()) std::printf("  %s", s.message.c_str());
  std::printf("\n");
  std::fflush(stdout);
}

/// Handles the bus until `done(status)` holds for a status received or the time-out; returns the
/// last status seen.
std::optional<Status> watch(
    sg::Bus& bus, double timeout, bool follow, const std::function<bool(const Status&)>& done,
    const std::function<void()>& meanwhile = [] {}) {
  std::optional<Status> last;
  bool finished = false;
  bus.subscribe<Status>("GRASP_STATUS", [&](const Status& s, const sg::ReceiveInfo&) {
    if (finished) return;
    if (follow && (!last || last->state != s.state || last->activity != s.activity ||
                   last->outcome != s.outcome || last->message != s.message)) {
      print(s);
    }
    last = s;
    finished = done(s);
  });
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  while (!sg::shutdown_requested() && std::chrono::steady_clock::now() < give_up && !finished) {
    bus.handle(std::chrono::milliseconds(50));
    meanwhile();
  }
  return last;
}

/// Exit code of a command that sg-grasp refused (command_result not RESULT_ACCEPTED).
constexpr int kRefused = 4;

int send(sg::Bus& bus, sg::auth::LabAccess& lab, int8_t command, double standoff, bool wait,
         double timeout) {
  Cmd c{};
  c.utime = sg::now_utime();
  c.sequence = c.utime;
  c.command = command;
  c.standoff = standoff;
  c.sender = "sg-grasp-ctl";
  lab.sign("GRASP_COMMAND", c);
  bus.publish("GRASP_COMMAND", c);
  // The answer is the first status whose command_sequence is ours; then, for --wait, the
  // command has run its course: tracking, the grasp judged, or idle.
  std::optional<int8_t> result;
  const auto finished = [&](const Status& s) {
    if (!result) {
      if (s.command_sequence != c.sequence) return false;
      result = s.command_result;
    }
    if (*result != Status::RESULT_ACCEPTED || !wait) return true;
    if (command == Cmd::COMMAND_TRACK) return s.activity == Status::ACTIVITY_TRACKING;
    if (command == Cmd::COMMAND_GRASP)
      return s.activity != Status::ACTIVITY_GRASPING && s.outcome != Status::OUTCOME_NONE;
    return s.activity == Status::ACTIVITY_IDLE;
  };
  // The bus may lose the command or its answer: the very same message again every 0.5 s until
  // the answer comes (sg-grasp answers a resend with the first answer and does nothing twice).
  auto resend_at = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
  const auto last = watch(
      bus, timeout, wait, [&](const Status& s) { return finished(s); },
      [&] {
        if (result || std::chrono::steady_clock::now() < resend_at) return;
        bus.publish("GRASP_COMMAND", c);
        resend_at = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
      });
  if (!last) throw std::runtime_error("no GRASP_STATUS: is sg-grasp running on this bus?");
  if (!result) throw std::runtime_error("sg-grasp did not answer the command within the time-out");
  if (*result != Status::RESULT_ACCEPTED) {
    print(*last);
    std::fprintf(stderr, "sg-grasp-ctl: %s: %s\n", sg::grasp_command_result_name(*result),
                 last->command_reason.c_str());
    return kRefused;
  }
  if (!finished(*last)) throw std::runtime_error("the command did not finish within the time-out");
  print(*last);
  if (command == Cmd::COMMAND_GRASP && wait)
    return last->outcome == Status::OUTCOME_SUCCESS ? 0 : 3;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Commands sg-grasp (GRASP_COMMAND) and prints GRASP_STATUS.", "sg-grasp-ctl"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  double standoff = 0, timeout = 10;
  bool wait = false, follow = false;
  app.add_option("--timeout", timeout, "seconds to wait for sg-grasp (default 10; 60 with --wait)");
  app.add_flag("--wait", wait,
               "wait until the command has run its course (grasp: exit 0 on "
               "success, 3 on failure)");
  app.footer(
      "Exit status: 0 done, 3 the grasp failed (--wait), 4 sg-grasp refused the command "
      "(its reason on stderr; also an unauthenticated one), 2 no lab key, 1 any other error.");
  app.require_subcommand(1);
  auto* track = app.add_subcommand("track", "follow the predicted ball at a stand-off above it");
  track->add_option("--standoff", standoff, "m above the ball (default: sg-grasp's, 0.10)")
      ->check(CLI::Range(0.0, 0.5));
  auto* grasp = app.add_subcommand("grasp", "approach, close the hand, lift (q1..q4)");
  auto* release = app.add_subcommand("release", "open the hand (a0)");
  auto* abort = app.add_subcommand("abort", "stop the arm and open the hand");
  auto* home = app.add_subcommand("home", "send the arm to its ready position");
  auto* status = app.add_subcommand("status", "print GRASP_STATUS");
  status->add_flag("--follow", follow, "keep printing changes until Ctrl-C");
  return sg::run_program(app, argc, argv, [&] {
    sg::load_common(common);
    sg::install_shutdown_handlers();
    sg::Bus bus(common.lcm_url);
    if (wait && app.get_option("--timeout")->count() == 0) timeout = 60;
    if (*status) {
      sg::auth::guard_if_key(bus, app.get_name(), key_options);
      const auto last =
          watch(bus, follow ? 1e9 : timeout, follow, [&](const Status&) { return !follow; });
      if (!last) throw std::runtime_error("no GRASP_STATUS: is sg-grasp running on this bus?");
      if (!follow) print(*last);
      return 0;
    }
    const int8_t command = *track     ? Cmd::COMMAND_TRACK
                           : *grasp   ? Cmd::COMMAND_GRASP
                           : *release ? Cmd::COMMAND_RELEASE
                           : *abort   ? Cmd::COMMAND_ABORT
                                      : Cmd::COMMAND_HOME;
    (void)home;
    return sg::auth::with_lab_access(app.get_name(), key_options, [&](sg::auth::LabAccess& lab) {
      lab.guard(bus);
      return send(bus, lab, command, standoff, wait, timeout);
    });
  });
}
