// sg-arm-driver: the CRS arm's C550 controller on a serial line (section 6). Subscribes to
// ARM_COMMAND, validates every command (finite, newer sequence, reachable, within joint limits and
// the workspace), keeps one controller interaction in flight with the newest command waiting
// (latest wins), and publishes ARM_STATUS at --status-rate and on every change. Reconnects with
// back-off when the device vanishes. The same binary drives a real C550 or sg-c550-sim.
//
//   sg-arm-driver --device /dev/ttyUSB0              # a real C550 at 38,400 8N1
//   sg-arm-driver --device /tmp/c550                  # sg-c550-sim --link /tmp/c550

#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "arm_driver/arm_driver.hpp"
#include "arm_driver/serial_port.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"

namespace {

struct Options {
  std::string device;
  int baud = 0;
  std::string framing;
  int slave = 0;
  double status_rate = 0;
};

struct Settings {
  std::string device;
  sg::arm::SerialSettings serial;
  sg::arm::DriverSettings driver;
  double status_rate = 20;
};

Settings load_settings(const sg::Config& c, const Options& o) {
  Settings s;
  s.device = o.device.empty() ? c.get<std::string>("arm_driver.device", "") : o.device;
  s.serial.baud = o.baud > 0 ? o.baud : c.get<int>("arm_driver.baud", 38400);
  sg::arm::parse_framing(o.framing.empty() ? c.get<std::string>("arm_driver.framing", "8N1")
                                           : o.framing,
                         s.serial);
  s.driver.slave = o.slave > 0 ? o.slave : c.get<int>("arm_driver.slave", 1);
  s.status_rate = o.status_rate > 0 ? o.status_rate : c.get<double>("arm_driver.status_rate_hz", 20);
  auto& t = s.driver.timing;
  t.byte_timeout = std::chrono::milliseconds(c.get<int>("arm_driver.byte_timeout_ms", 200));
  t.reply_timeout = std::chrono::milliseconds(c.get<int>("arm_driver.reply_timeout_ms", 1000));
  t.motion_reply = std::chrono::milliseconds(c.get<int>("arm_driver.motion_reply_ms", 3000));
  s.driver.reconnect_max = c.get<double>("arm_driver.reconnect_max", 2.0);
  if (s.device.empty()) {
    throw std::runtime_error("no serial device: give --device PATH (or arm_driver.device)");
  }
  if (s.driver.slave < 1 || s.driver.slave > 127) throw c.error_at("arm_driver.slave", "1..127");
  if (!(s.status_rate >= 10)) throw c.error_at("arm_driver.status_rate_hz", "at least 10 Hz");
  if (t.byte_timeout.count() <= 0 || t.reply_timeout.count() <= 0 || t.motion_reply.count() <= 0)
    throw c.error_at("arm_driver.byte_timeout_ms", "time-outs must be positive");
  return s;
}

int run(const std::string& url, const sg::arm::ArmGeometry& geometry, const Settings& s) {
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  sg::arm::SerialPort::open(s.device, s.serial).reset();  // fail now, clearly, on a bad path
  sg::arm::ArmDriver driver(geometry, s.driver, [&] {
    return std::unique_ptr<sg::arm::ByteStream>(sg::arm::SerialPort::open(s.device, s.serial));
  });
  bus.subscribe<stereograsp::arm_cmd_t>(
      "ARM_COMMAND",
      [&](const stereograsp::arm_cmd_t& command, const sg::ReceiveInfo&) { driver.submit(command); });
  spdlog::info("driving the C550 on {} at {}", s.device, sg::arm::describe(s.serial));
  std::jthread worker([&](std::stop_token stop) { driver.run(stop); });
  const auto period = std::chrono::duration<double>(1.0 / s.status_rate);
  auto next = std::chrono::steady_clock::now();
  uint64_t published_version = ~0ull;
  while (!sg::shutdown_requested()) {
    bus.handle(std::chrono::milliseconds(5));
    auto [status, version] = driver.status();
    const auto now = std::chrono::steady_clock::now();
    if (version != published_version || now >= next) {
      status.utime = sg::now_utime();
      bus.publish("ARM_STATUS", status);
      published_version = version;
      next = now + std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    }
  }
  spdlog::info("stopping");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Drives a CRS arm through its C550 controller on a serial line: ARM_COMMAND in, "
               "ARM_STATUS out (docs/arm.md).",
               "sg-arm-driver"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  Options o;
  app.add_option("--device", o.device,
                 "serial device: /dev/ttyS0, /dev/ttyUSB0, or sg-c550-sim's pseudo-terminal");
  app.add_option("--baud", o.baud, "baud rate (default 38400)");
  app.add_option("--framing", o.framing, "data bits, parity, stop bits (default 8N1)");
  app.add_option("--slave", o.slave, "the controller's ACI slave number 1..127 (default 1)");
  app.add_option("--status-rate", o.status_rate, "ARM_STATUS rate in Hz, at least 10 (default 20)");
  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    const Settings settings = load_settings(config, o);
    return run(common.lcm_url, sg::arm::load_arm_geometry(config), settings);
  });
}
