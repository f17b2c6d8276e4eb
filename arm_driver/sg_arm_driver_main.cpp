// sg-arm-driver: the CRS arm's C550 controller on a serial line (section 6). Subscribes to
// ARM_COMMAND, validates every command (finite, newer sequence, reachable, within joint limits and
// the workspace), keeps one controller interaction in flight with the newest command waiting
// (latest wins), and publishes ARM_STATUS at --status-rate and on every change. Reconnects with
// back-off when the device vanishes. The same binary drives a real C550 or sg-c550-sim.
// Every ARM_COMMAND must be signed with the lab key (docs/security.md): an unsigned, forged,
// replayed or stale one is refused (ARM_STATUS: last_rejected_sequence, "unauthenticated: ...")
// before it reaches the validator, so it cannot move the arm or lock its sender out. One
// commander at a time holds the lease (docs/arm.md): another sender's command is refused (counted
// in PROCESS_STATUS, the log rate-limited), and when the holder's heartbeats stop for
// arm_driver.commander_timeout the watchdog stops a moving arm (ABORT, the gripper kept).
//
//   sg-arm-driver --device /dev/ttyUSB0              # a real C550 at 38,400 8N1
//   sg-arm-driver --device /tmp/c550                  # sg-c550-sim --link /tmp/c550
//   sg-arm-driver --device /tmp/c550 --key lab.key    # a key other than $SG_LAB_KEY's

#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "arm_driver/arm_driver.hpp"
#include "arm_driver/driver_settings_io.hpp"
#include "arm_driver/serial_port.hpp"
#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/change_or_period.hpp"
#include "common/clock.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"

namespace {

/// Opens the device once, to fail now and clearly on a bad path; with device_wait, retries every
/// 0.5 s for that long while PROCESS_STATUS says "starting: waiting for DEVICE". False when a
/// shutdown came first.
bool wait_for_device(sg::Bus& bus, const sg::arm::ArmDriverSettings& s) {
  const auto until =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(s.device_wait);
  bus.announce("sg-arm-driver", stereograsp::process_status_t::STATE_STARTING,
               "opening " + s.device);
  for (bool told = false;; told = true) {
    try {
      sg::arm::SerialPort::open(s.device, s.serial).reset();
      bus.set_state(stereograsp::process_status_t::STATE_READY);
      return true;
    } catch (const std::exception& e) {
      if (std::chrono::steady_clock::now() >= until) throw;
      const std::string why = "waiting for " + s.device + ": " + e.what();
      if (!told) spdlog::info("{} (up to {} s)", why, s.device_wait);
      bus.set_state(stereograsp::process_status_t::STATE_STARTING, why);
    }
    const auto retry = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
    while (std::chrono::steady_clock::now() < retry) {
      if (sg::shutdown_requested()) return false;
      bus.handle(std::chrono::milliseconds(50));
    }
  }
}

int run(const std::string& url, const sg::arm::ArmGeometry& geometry,
        const sg::arm::ArmDriverSettings& s, sg::auth::LabAccess& lab) {
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  lab.guard(bus);
  if (!wait_for_device(bus, s)) return 0;  // asked to stop while waiting
  sg::arm::DriverSettings settings = s.driver;
  settings.start_utime = sg::now_utime();  // ARM_STATUS.driver_start_utime: a restart shows
  sg::arm::ArmDriver driver(geometry, settings, [&] {
    return std::unique_ptr<sg::arm::ByteStream>(sg::arm::SerialPort::open(s.device, s.serial));
  });
  bus.subscribe<stereograsp::arm_cmd_t>(
      "ARM_COMMAND", [&](const stereograsp::arm_cmd_t& command, const sg::ReceiveInfo& info) {
        const std::string why = lab.refusal(info.channel, command, sg::now_utime());
        if (!why.empty()) {
          driver.refuse(command, why);
          bus.note_refused(info.channel, why);  // counted, and logged rate-limited
        } else if (const auto r = driver.submit(command); r.outcome == r.kRefused) {
          bus.note_refused(info.channel, "from '" + command.sender + "': " + r.reason);
        }
      });
  spdlog::info("driving the C550 on {} at {}", s.device, sg::arm::describe(s.serial));
  std::jthread worker([&](std::stop_token stop) { driver.run(stop); });
  sg::ChangeOrPeriod rule(1.0 / s.status_rate_hz);
  while (!sg::shutdown_requested()) {
    bus.handle(std::chrono::milliseconds(5));
    auto [status, version] = driver.status();
    if (rule.due(version, sg::system_clock().now())) {
      status.utime = sg::now_utime();
      bus.publish("ARM_STATUS", status);
    }
  }
  spdlog::info("stopping");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Drives a CRS arm through its C550 controller on a serial line: ARM_COMMAND in, "
      "ARM_STATUS out (docs/arm.md).",
      "sg-arm-driver"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  const auto keys = sg::declared_keys(sg::arm::read_arm_driver_settings);
  common.flags.add(app, "--device", "arm_driver.device", keys);
  common.flags.add(app, "--device-wait", "arm_driver.device_wait", keys);
  common.flags.add(app, "--baud", "arm_driver.baud", keys);
  common.flags.add(app, "--framing", "arm_driver.framing", keys);
  common.flags.add(app, "--slave", "arm_driver.slave", keys);
  common.flags.add(app, "--status-rate", "arm_driver.status_rate_hz", keys);
  common.flags.add(app, "--commander-timeout", "arm_driver.commander_timeout", keys);
  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    const sg::arm::ArmDriverSettings settings = sg::arm::read_arm_driver_settings(config);
    if (settings.device.empty())
      throw std::runtime_error("no serial device: give --device PATH (or arm_driver.device)");
    return sg::auth::with_lab_access(app.get_name(), key_options, [&](sg::auth::LabAccess& lab) {
      return run(common.lcm_url, sg::arm::load_arm_geometry(config), settings, lab);
    });
  });
}
