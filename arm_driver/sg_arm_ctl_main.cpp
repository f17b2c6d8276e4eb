// sg-arm-ctl: the arm from the lab bench. Sends one ARM_COMMAND, keeps the commander lease with
// heartbeats until sg-arm-driver reports it executed and the arm at rest (or rejected, with the
// reason), then releases the lease; or prints ARM_STATUS. The lease is taken only when it is free
// (or its holder silent), or with --take-over; a refusal prints the holder and exits 1. Ctrl-C
// while the arm moves sends STOP. Commands are signed with the lab key (--key, default
// $SG_LAB_KEY or ~/.config/stereograsp/lab.key; docs/security.md).
//
//   sg-arm-ctl move 0.45 0.0 0.25                   # tool centre point (m), tool pointing down
//   sg-arm-ctl move 0.45 0.0 0.25 --rpy 3.1416 0 0 --speed 0.2
//   sg-arm-ctl --take-over home                     # even while sg-grasp holds the arm
//   sg-arm-ctl joints 0 10 20 0 60 0 --deg
//   sg-arm-ctl open | close | home | stop
//   sg-arm-ctl status [--follow]

#include <cmath>
#include <cstdio>
#include <numbers>

#include "arm_driver/arm_commander.hpp"
#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"

namespace {

using Cmd = stereograsp::arm_cmd_t;
using Status = stereograsp::arm_status_t;

const char* state_name(int8_t state) {
  switch (state) {
    case Status::STATE_IDLE:
      return "IDLE";
    case Status::STATE_MOVING:
      return "MOVING";
    case Status::STATE_ERROR:
      return "ERROR";
    case Status::STATE_DISCONNECTED:
      return "DISCONNECTED";
    default:
      return "?";
  }
}

const char* gripper_name(int8_t gripper) {
  return gripper == Status::GRIPPER_OPEN     ? "open"
         : gripper == Status::GRIPPER_CLOSED ? "closed"
                                             : "unknown";
}

void print_status(const Status& s) {
  const double deg = 180.0 / std::numbers::pi;
  std::printf(
      "%-12s tool (%.4f, %.4f, %.4f) m  rpy (%.1f, %.1f, %.1f) deg  gripper %s\n"
      "             joints (%.2f, %.2f, %.2f, %.2f, %.2f, %.2f) deg  executed #%lld  "
      "interaction %.3f s  speed %.0f%%\n",
      state_name(s.state), s.tool_position[0], s.tool_position[1], s.tool_position[2],
      s.tool_orientation[0] * deg, s.tool_orientation[1] * deg, s.tool_orientation[2] * deg,
      gripper_name(s.gripper), s.joints[0] * deg, s.joints[1] * deg, s.joints[2] * deg,
      s.joints[3] * deg, s.joints[4] * deg, s.joints[5] * deg,
      static_cast<long long>(s.last_executed_sequence), s.interaction_time, s.speed * 100);
  if (!s.error.empty()) std::printf("             error: %s\n", s.error.c_str());
  std::fflush(stdout);
}

Cmd make_command(int8_t mode, double speed) {
  Cmd c{};
  c.utime = sg::now_utime();
  c.source_utime = 0;
  c.target_utime = 0;
  c.sequence = c.utime;  // strictly increasing across invocations of this program
  c.mode = mode;
  c.gripper = Cmd::GRIPPER_KEEP;
  c.speed = speed;
  c.sender = "sg-arm-ctl";  // the signer makes it sg-arm-ctl@host:pid
  return c;
}

/// Sends `command` through an ArmCommander (heartbeats while it runs, the lease released after)
/// and prints how it ended. Returns the exit code.
int send(sg::Bus& bus, sg::auth::LabAccess& lab, const Cmd& command, double timeout) {
  sg::arm::ArmCommander commander(bus, lab);
  const sg::arm::CommandReport r = commander.execute(command, timeout);
  using Report = sg::arm::CommandReport;
  if (!commander.have_status()) {
    throw std::runtime_error(
        "no ARM_STATUS on this bus: is sg-arm-driver running (same --lcm-url)?");
  }
  switch (r.result) {
    case Report::kExecuted:
      std::printf("command #%lld executed\n", static_cast<long long>(command.sequence));
      print_status(commander.status());
      return 0;
    case Report::kRejected:
    case Report::kTakenOver:
    case Report::kInterrupted:
      std::printf("command #%lld %s: %s\n", static_cast<long long>(command.sequence),
                  r.result == Report::kRejected ? "rejected" : "not completed", r.reason.c_str());
      return 1;
    case Report::kTimedOut:
      break;
  }
  print_status(commander.status());
  throw std::runtime_error(r.reason);
}

int status(sg::Bus& bus, bool follow, double timeout) {
  bool have = false;
  bus.subscribe<Status>("ARM_STATUS", [&](const Status& s, const sg::ReceiveInfo&) {
    if (!follow && have) return;
    have = true;
    print_status(s);
  });
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  while (!sg::shutdown_requested() && (follow || !have) &&
         (follow || std::chrono::steady_clock::now() < give_up)) {
    bus.handle(std::chrono::milliseconds(50));
  }
  if (!have) throw std::runtime_error("no ARM_STATUS within " + std::to_string(timeout) + " s");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Commands the arm through sg-arm-driver (ARM_COMMAND) and prints ARM_STATUS.",
               "sg-arm-ctl"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  double speed = 0.5, timeout = 10;
  bool wait_idle = false, degrees = false, follow = false, take_over = false;
  std::vector<double> xyz, rpy, joints;
  app.add_option("--speed", speed, "fraction of the joint speed limits, (0, 1] (default 0.5)");
  app.add_option("--timeout", timeout,
                 "seconds to wait for the command to be executed and the arm at rest (default 10)");
  app.add_flag("--wait", wait_idle,
               "accepted for old scripts and ignored: every command now waits until the arm is "
               "at rest");
  app.add_flag("--take-over", take_over,
               "take the commander lease even when another sender holds it (sg-grasp, say)");
  app.require_subcommand(1);
  auto* move = app.add_subcommand("move", "move the tool centre point to X Y Z (m)");
  move->add_option("X Y Z", xyz, "robot base frame, metres")->expected(3)->required();
  move->add_option(
          "--rpy", rpy,
          "tool roll pitch yaw, radians (default: pointing down, the gripper square to the "
          "base, pi 0 atan2(Y,X)+pi, which keeps joint 6 near zero)")
      ->expected(3);
  auto* joint_cmd = app.add_subcommand("joints", "move to joint angles J1..J6 (radians)");
  joint_cmd->add_option("J", joints, "six joint angles")->expected(6)->required();
  joint_cmd->add_flag("--deg", degrees, "the angles are in degrees");
  auto* open = app.add_subcommand("open", "open the gripper");
  auto* close = app.add_subcommand("close", "close the gripper");
  auto* home = app.add_subcommand("home", "go to the ready position");
  auto* stop = app.add_subcommand("stop", "stop the arm where it is");
  auto* status_cmd = app.add_subcommand("status", "print ARM_STATUS");
  status_cmd->add_flag("--follow", follow, "keep printing until Ctrl-C");
  return sg::run_program(app, argc, argv, [&] {
    sg::load_common(common);
    sg::install_shutdown_handlers();
    sg::Bus bus(common.lcm_url);
    if (*status_cmd) {
      sg::auth::guard_if_key(bus, app.get_name(), key_options);
      return status(bus, follow, timeout);
    }
    Cmd c = make_command(Cmd::MODE_STOP, speed);
    if (*move) {
      c.mode = Cmd::MODE_CARTESIAN;
      if (rpy.empty())
        rpy = {std::numbers::pi, 0,
               std::remainder(std::atan2(xyz[1], xyz[0]) + std::numbers::pi, 2 * std::numbers::pi)};
      for (int i = 0; i < 3; ++i) c.position[i] = xyz[i], c.orientation[i] = rpy[i];
    } else if (*joint_cmd) {
      c.mode = Cmd::MODE_JOINTS;
      for (int i = 0; i < 6; ++i)
        c.joints[i] = degrees ? joints[i] * std::numbers::pi / 180 : joints[i];
    } else if (*open || *close) {
      c.mode = Cmd::MODE_GRIPPER_ONLY;
      c.gripper = *open ? Cmd::GRIPPER_OPEN : Cmd::GRIPPER_CLOSE;
    } else if (*home) {
      c.mode = Cmd::MODE_HOME;
    } else if (!*stop) {
      throw std::runtime_error("no command");
    }
    c.take_over = take_over;
    return sg::auth::with_lab_access(app.get_name(), key_options, [&](sg::auth::LabAccess& lab) {
      lab.guard(bus);
      return send(bus, lab, c, timeout);
    });
  });
}
