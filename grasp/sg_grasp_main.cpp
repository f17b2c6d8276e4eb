// sg-grasp: the grasp state machine (section 6, figure 4) over LCM. Reads the predicted path
// (OBJECT_TRAJECTORY), the measurements (OBJECT_POSITION), the arm (ARM_STATUS) and the operator
// (GRASP_COMMAND); sends ARM_COMMAND, one at a time, each aimed where the ball will be when the
// gripper gets there; publishes GRASP_STATUS on every change and at --status-rate.
//
//   sg-grasp                         # then: sg-grasp-ctl track; sg-grasp-ctl grasp
//   sg-grasp --no-prediction         # aim at the last measured position (the baseline)

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>

#include "grasp/grasp_machine.hpp"
#include "grasp/grasp_node.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"
#include "stereograsp/grasp_command_t.hpp"
#include "stereograsp/grasp_status_t.hpp"
#include "stereograsp/point3_t.hpp"
#include "stereograsp/trajectory_t.hpp"

namespace {

struct Options {
  bool no_prediction = false;
  double standoff = -1, speed = -1, status_rate = 4;
};

/// The grasp settings from `grasp.*` in the config, flags winning.
sg::grasp::GraspSettings load_settings(const sg::Config& c, const Options& o) {
  sg::grasp::GraspSettings s;
  s.standoff = o.standoff >= 0 ? o.standoff : c.get<double>("grasp.standoff", s.standoff);
  s.speed = o.speed > 0 ? o.speed : c.get<double>("grasp.speed", s.speed);
  s.lift = c.get<double>("grasp.lift", s.lift);
  s.backoff = c.get<double>("grasp.backoff", s.backoff);
  s.max_trajectory_age = c.get<double>("grasp.max_trajectory_age", s.max_trajectory_age);
  s.success_distance = c.get<double>("grasp.success_distance", s.success_distance);
  s.judge_time = c.get<double>("grasp.judge_time", s.judge_time);
  s.default_delay = c.get<double>("grasp.default_delay", s.default_delay);
  s.use_prediction = !o.no_prediction && c.get<bool>("grasp.use_prediction", true);
  auto& i = s.interception;
  i.table_z = c.get<double>("grasp.table_z", i.table_z);
  i.table_margin = c.get<double>("grasp.table_margin", i.table_margin);
  i.wrist_min = c.get<double>("grasp.wrist_min", i.wrist_min);
  i.wrist_max = c.get<double>("grasp.wrist_max", i.wrist_max);
  if (!(s.standoff >= 0 && s.standoff <= 0.5)) throw c.error_at("grasp.standoff", "0 to 0.5 m");
  if (!(s.speed > 0 && s.speed <= 1)) throw c.error_at("grasp.speed", "in (0, 1]");
  if (!(s.lift > 0 && s.lift <= 0.5)) throw c.error_at("grasp.lift", "in (0, 0.5] m");
  if (!(s.max_trajectory_age > 0)) throw c.error_at("grasp.max_trajectory_age", "positive");
  if (!(s.judge_time > 0)) throw c.error_at("grasp.judge_time", "positive");
  if (!(i.wrist_min < i.wrist_max)) throw c.error_at("grasp.wrist_min", "below wrist_max");
  return s;
}

int run(const std::string& url, const sg::arm::ArmGeometry& geometry,
        const sg::grasp::GraspSettings& settings, double status_rate) {
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  sg::grasp::GraspNode node(geometry, settings, sg::now_utime(), 1.0 / status_rate);
  bus.subscribe<stereograsp::trajectory_t>("OBJECT_TRAJECTORY", [&](const auto& m, const auto&) {
    const std::string why = node.on_trajectory(m, sg::now_utime());
    if (!why.empty()) spdlog::warn("OBJECT_TRAJECTORY at {}: {}; ignored", m.utime, why);
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
  spdlog::info("grasping {} prediction", settings.use_prediction ? "with" : "WITHOUT");
  while (!sg::shutdown_requested()) {
    bus.handle(std::chrono::milliseconds(10));
    const sg::grasp::GraspNode::Output out = node.poll(sg::now_utime());
    if (out.arm_command) bus.publish("ARM_COMMAND", *out.arm_command);
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
  Options o;
  app.add_flag("--no-prediction", o.no_prediction,
               "aim at the last measured position instead of the predicted one (the baseline)");
  app.add_option("--standoff", o.standoff, "m above the ball while tracking (default 0.10)");
  app.add_option("--speed", o.speed, "arm speed, fraction of the joint limits (default 0.5)");
  app.add_option("--status-rate", o.status_rate, "GRASP_STATUS per second besides changes")
      ->check(CLI::Range(0.5, 100.0));
  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    return run(common.lcm_url, sg::arm::load_arm_geometry(config), load_settings(config, o),
               o.status_rate);
  });
}
