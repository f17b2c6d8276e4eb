#pragma once

#include <string>

#include "common/config.hpp"
#include "sim/c550_controller.hpp"

namespace sg::sim {

/// Faults on sg-c550-sim's line (docs/arm.md).
struct LineFaults {
  double garble_rate = 0;        ///< probability a byte the controller sends is replaced
  double drop_ack_rate = 0;      ///< probability an ACK the controller sends is lost
  double disconnect_after = 0;   ///< s until the line is closed once (0: never)
  double reconnect_after = 1.0;  ///< s without a line before a new pseudo-terminal opens
};

/// What sg-c550-sim is configured with: the `c550_sim` section.
struct C550SimSettings {
  int slave = 1;             ///< the ACI slave number
  C550Params controller;     ///< delays, seed, speed, gripper, holding
  std::string link;          ///< a symlink to the pseudo-terminal ("" = none)
  LineFaults faults;
  std::string log_commands;  ///< a file each RAPL-II command received is appended to
  double state_rate = 50;    ///< SIM_ARM_STATE per second
};

/// Reads the `c550_sim` section: every key range-checked, any other key of the section refused
/// with the nearest known one. Absent keys keep the structs' defaults.
C550SimSettings read_c550_sim_settings(const Config& config);

}  // namespace sg::sim
