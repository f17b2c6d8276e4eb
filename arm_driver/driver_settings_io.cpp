#include "arm_driver/driver_settings_io.hpp"

#include <stdexcept>

namespace sg::arm {
namespace {

/// A time-out in whole milliseconds, at least 1.
void milliseconds_key(Section& section, const std::string& key, std::chrono::milliseconds& value,
                      const std::string& help) {
  int64_t ms = value.count();
  section.number(key, ms, Range::closed(1, 600000), help);
  value = std::chrono::milliseconds(ms);
}

}  // namespace

ArmDriverSettings read_arm_driver_settings(const Config& config) {
  ArmDriverSettings s;
  Section a(config, "arm_driver");
  a.text("device", s.device, "serial device: /dev/ttyS0, /dev/ttyUSB0, or sg-c550-sim's");
  a.number("device_wait", s.device_wait, Range::closed(0, 3600),
           "s to wait at start for the device to appear (a C550 emulator started after the "
           "driver, a USB adapter plugged in), 0 to refuse a missing one at once");
  a.number("baud", s.serial.baud, Range::closed(1200, 230400), "baud rate");
  std::string framing = "8N1";
  a.text("framing", framing, "data bits, parity, stop bits");
  try {
    parse_framing(framing, s.serial);
  } catch (const std::invalid_argument& e) {
    throw a.error("framing", e.what());
  }
  a.number("slave", s.driver.slave, Range::closed(1, 127), "the controller's ACI slave number");
  a.number("status_rate_hz", s.status_rate_hz, Range::closed(10, 1000),
           "ARM_STATUS per second, also sent on every change");
  LinkTiming& t = s.driver.timing;
  milliseconds_key(a, "byte_timeout_ms", t.byte_timeout, "ms for an echo, an ACK to a block");
  milliseconds_key(a, "reply_timeout_ms", t.reply_timeout,
                   "ms for the ACK of a command that does not move the arm");
  milliseconds_key(a, "motion_reply_ms", t.motion_reply, "ms for the ACK of a motion command");
  a.number("max_speed", s.driver.max_speed, Range::above_to(0, 1),
           "fastest the driver lets the arm move, fraction of the joints' maximum speeds");
  a.number("reconnect_max", s.driver.reconnect_max, Range::closed(s.driver.reconnect_min, 3600),
           "s: the reconnect back-off doubles up to this");
  a.number("commander_timeout", s.driver.commander_timeout, Range::closed(0.2, 60),
           "s of silence after which the commander loses the lease and a moving arm is stopped "
           "(ABORT, gripper kept)");
  a.done();
  return s;
}

}  // namespace sg::arm
