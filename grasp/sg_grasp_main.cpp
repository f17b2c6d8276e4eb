// sg-grasp: the grasp state machine (section 6, figure 4) over LCM. Reads the predicted path
// (OBJECT_TRAJECTORY), the measurements (OBJECT_POSITION), the arm (ARM_STATUS) and the operator
// (GRASP_COMMAND); sends ARM_COMMAND, one at a time, each aimed where the ball will be when the
// gripper gets there, and heartbeats while it wants the arm (the driver's watchdog stops the arm
// when they stop); publishes GRASP_STATUS on every change and at --status-rate. It moves nothing
// until an operator asks.
//
//   sg-grasp                         # then: sg-grasp-ctl track; sg-grasp-ctl grasp
//   sg-grasp --no-prediction         # aim at the last measured position (the baseline)
//
// Its ARM_COMMAND are signed with the lab key, and GRASP_COMMAND must be (--key, default
// $SG_LAB_KEY or ~/.config/stereograsp/lab.key; docs/security.md).

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>

#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/process_watch.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "grasp/capture_clock.hpp"
#include "grasp/grasp_machine.hpp"
#include "grasp/grasp_node.hpp"
#include "grasp/grasp_settings.hpp"
#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"
#include "stereograsp/grasp_command_t.hpp"
#include "stereograsp/grasp_status_t.hpp"
#include "stereograsp/point3_t.hpp"
#include "stereograsp/trajectory_t.hpp"

namespace {

/// Puts the forecast on this host's clock (grasp/capture_clock.hpp), re-estimated once a second;
/// says so when the capture clock's offset changes by more than a millisecond, or cannot be used.
class CaptureClockFollower {
 public:
  CaptureClockFollower(sg::Bus& bus, sg::grasp::GraspNode& node) : bus_(bus), node_(node) {
    char name[256] = {};
    host_ = gethostname(name, sizeof name - 1) == 0 ? name : "?";
    bus.subscribe<stereograsp::process_status_t>(
        "PROCESS_STATUS",
        [this](const auto& s, const auto& info) { watch_.receive(s, info.recv_utime); });
  }
  void poll(int64_t now) {
    if (now < next_) return;
    next_ = now + 1'000'000;
    const auto e = sg::grasp::CaptureClock::estimate(watch_, *bus_.clock_sync(), host_);
    if (!e.usable) {
      if (!e.why.empty() && e.why != said_) spdlog::warn("{}", said_ = e.why);
      return;
    }
    if (std::llabs(e.offset_us - node_.capture_clock_offset()) > 1000 || e.host != host_said_) {
      spdlog::info(
          "capture clock: {} on {}, {:+.1f} ms ± {:.1f} ms from this host's; forecast "
          "times are put on this host's clock",
          e.source, e.host, e.offset_us / 1e3, e.error_us / 1e3);
      host_said_ = e.host;
    }
    node_.set_capture_clock_offset(e.offset_us);
  }

 private:
  sg::Bus& bus_;
  sg::grasp::GraspNode& node_;
  sg::ProcessWatch watch_;
  std::string host_, said_, host_said_;
  int64_t next_ = 0;
};

int run(const std::string& url, const sg::arm::ArmGeometry& geometry,
        const sg::grasp::GraspSettings& settings, double status_rate, sg::auth::LabAccess& lab) {
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  lab.guard(bus);  // believes OBJECT_TRAJECTORY, ARM_STATUS, ... only from their publishers
  bus.announce("sg-grasp");
  sg::grasp::GraspNode node(geometry, settings, sg::now_utime(), 1.0 / status_rate);
  if (lab.secure() && !lab.command_key())
    throw std::runtime_error("the credentials hold no command key: sg-grasp's own are needed");
  if (lab.command_key()) node.require_signed_commands(*lab.command_key(), "GRASP_COMMAND");
  bus.subscribe<stereograsp::trajectory_t>("OBJECT_TRAJECTORY", [&](const auto& m, const auto&) {
    const std::string why = node.on_trajectory(m, sg::now_utime());
    if (!why.empty()) bus.note_refused("OBJECT_TRAJECTORY", why);  // counted, logged sparingly
  });
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION",
                                       [&](const auto& m, const auto&) { node.on_position(m); });
  bus.subscribe<stereograsp::arm_status_t>(
      "ARM_STATUS", [&](const auto& m, const auto&) { node.on_arm_status(m, sg::now_utime()); });
  bus.subscribe<stereograsp::grasp_command_t>("GRASP_COMMAND", [&](const auto& m, const auto&) {
    const sg::grasp::CommandRecord& r = node.on_command(m, sg::now_utime());
    if (r.reply.result != sg::grasp::CommandResult::kAccepted) {
      spdlog::warn("GRASP_COMMAND {} from '{}': {}: {}", m.sequence, m.sender,
                   to_string(r.reply.result), r.reply.reason);
    }
  });
  CaptureClockFollower capture_clock(bus, node);
  spdlog::info("grasping {} prediction", settings.use_prediction ? "with" : "WITHOUT");
  while (!sg::shutdown_requested()) {
    bus.handle(std::chrono::milliseconds(10));
    capture_clock.poll(sg::now_utime());
    const sg::grasp::GraspNode::Output out = node.poll(sg::now_utime());
    for (const auto& arm_command : {out.arm_command, out.lease}) {  // the request first
      if (!arm_command) continue;
      stereograsp::arm_cmd_t command = *arm_command;
      lab.sign("ARM_COMMAND", command);  // every one, resends and heartbeats too: a new counter
      bus.publish("ARM_COMMAND", command);
    }
    if (out.status) bus.publish("GRASP_STATUS", *out.status);
    if (!out.changed_summary.empty()) spdlog::info("{}", out.changed_summary);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "The grasp state machine: tracks the predicted ball with the arm and grasps it "
      "(GRASP_COMMAND in; ARM_COMMAND, GRASP_STATUS out; docs/grasping.md).",
      "sg-grasp"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  const auto keys = sg::declared_keys(sg::grasp::read_grasp_settings);
  common.flags.add_switch(app, "--no-prediction", "grasp.use_prediction", "false",
                          "aim at the last measured position instead of the predicted one");
  common.flags.add(app, "--standoff", "grasp.standoff", keys);
  common.flags.add(app, "--speed", "grasp.speed", keys);
  common.flags.add(app, "--confidence", "grasp.confidence", keys);
  common.flags.add(app, "--max-wait", "grasp.max_wait", keys);
  double status_rate = 4;
  app.add_option("--status-rate", status_rate, "GRASP_STATUS per second besides changes")
      ->check(CLI::Range(0.5, 100.0))
      ->capture_default_str();
  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    const sg::arm::ArmGeometry geometry = sg::arm::load_arm_geometry(config);
    const sg::grasp::GraspSettings settings = sg::grasp::read_grasp_settings(config);
    return sg::auth::with_lab_access(app.get_name(), key_options, [&](sg::auth::LabAccess& lab) {
      return run(common.lcm_url, geometry, settings, status_rate, lab);
    });
  });
}
