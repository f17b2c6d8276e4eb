#pragma once

#include <string>

#include "arm_driver/arm_driver.hpp"
#include "arm_driver/serial_port.hpp"
#include "common/config.hpp"

namespace sg::arm {

/// What sg-arm-driver is configured with: the `arm_driver` section (docs/arm.md).
struct ArmDriverSettings {
  std::string device;  ///< the serial device; "" until a flag or the file names one
  SerialSettings serial;
  DriverSettings driver;
  double status_rate_hz = 20;  ///< ARM_STATUS per second (also on every change)
  /// s to wait for the device to appear at start (PROCESS_STATUS says "starting" meanwhile);
  /// 0: refuse a missing device at once.
  double device_wait = 0;
};

/// Reads the `arm_driver` section: every key range-checked, any other key of the section
/// refused with the nearest known one. Absent keys keep the structs' defaults.
ArmDriverSettings read_arm_driver_settings(const Config& config);

}  // namespace sg::arm
