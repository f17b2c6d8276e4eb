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
#include <map>

#include "grasp/grasp_machine.hpp"
#include "grasp/grasp_messages.hpp"
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

using sg::grasp::GraspMachine;

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

/// The fields a person watches: a change of any is published and logged at once.
std::string summary(const sg::grasp::GraspStatusView& v) {
  return std::string(to_string(v.state)) + ", " + to_string(v.activity) + ", last " +
         to_string(v.last_action) + ", outcome " + to_string(v.outcome) +
         (v.message.empty() ? "" : ": " + v.message);
}

int run(const std::string& url, const sg::arm::ArmGeometry& geometry,
        const sg::grasp::GraspSettings& settings, double status_rate) {
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  GraspMachine machine(geometry, settings, sg::now_utime());
  std::map<std::string, int64_t> last_command;  // per sender
  int64_t trajectory_utime = 0;                 // the newest OBJECT_TRAJECTORY's
  bus.subscribe<stereograsp::trajectory_t>("OBJECT_TRAJECTORY", [&](const auto& m, const auto&) {
    trajectory_utime = m.utime;
    std::string why;
    if (auto path = sg::grasp::path_from(m, &why)) {
      machine.on_trajectory(*path, m.source_utime, sg::now_utime());
    } else {
      spdlog::warn("OBJECT_TRAJECTORY at {}: {}; ignored", m.utime, why);
    }
  });
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION", [&](const auto& m, const auto&) {
    const Eigen::Vector3d p(m.position[0], m.position[1], m.position[2]);
    machine.on_measurement(m.visible && p.allFinite() ? std::optional(p) : std::nullopt, m.utime);
  });
  bus.subscribe<stereograsp::arm_status_t>("ARM_STATUS", [&](const auto& m, const auto&) {
    machine.on_arm_status(sg::grasp::arm_view_of(m), sg::now_utime());
  });
  bus.subscribe<stereograsp::grasp_command_t>("GRASP_COMMAND", [&](const auto& m, const auto&) {
    auto [it, fresh] = last_command.try_emplace(m.sender, m.sequence);
    if (!fresh && m.sequence <= it->second) {
      spdlog::warn("GRASP_COMMAND {} from '{}': sequence not newer than {}; ignored", m.sequence,
                   m.sender, it->second);
      return;
    }
    it->second = m.sequence;
    if (m.command < 1 || m.command > 5) {
      spdlog::warn("GRASP_COMMAND {} from '{}': unknown command {}", m.sequence, m.sender,
                   static_cast<int>(m.command));
      return;
    }
    if (!std::isfinite(m.standoff) || m.standoff < 0 || m.standoff > 0.5) {
      spdlog::warn("GRASP_COMMAND {}: stand-off {} m outside 0..0.5; ignored", m.sequence,
                   m.standoff);
      return;
    }
    machine.on_command(static_cast<sg::grasp::GraspCommand>(m.command), m.standoff, sg::now_utime());
  });
  spdlog::info("grasping {} prediction", settings.use_prediction ? "with" : "WITHOUT");
  const auto period = std::chrono::duration<double>(1.0 / status_rate);
  auto next = std::chrono::steady_clock::now();
  std::string last_summary;
  while (!sg::shutdown_requested()) {
    bus.handle(std::chrono::milliseconds(10));
    const int64_t now = sg::now_utime();
    if (auto request = machine.take_request(now)) {
      // utime: the message time of the decision, the newest trajectory's (the clock's before one).
      bus.publish("ARM_COMMAND",
                  sg::grasp::to_arm_cmd(*request, trajectory_utime ? trajectory_utime : now));
    }
    const std::string s = summary(machine.status());
    const auto t = std::chrono::steady_clock::now();
    if (s != last_summary || t >= next) {
      bus.publish("GRASP_STATUS", sg::grasp::to_grasp_status(machine.status(), now));
      if (s != last_summary) spdlog::info("{}", s);
      last_summary = s;
      next = t + std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    }
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
