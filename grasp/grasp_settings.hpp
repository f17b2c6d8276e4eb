#pragma once

#include "common/config.hpp"
#include "grasp/grasp_machine.hpp"

namespace sg::grasp {

/// The `grasp` section of the configuration (docs/grasping.md): every key range-checked, any
/// other key of the section refused with the nearest known one. Absent keys keep
/// GraspSettings' defaults, which config/stereograsp.yaml repeats.
GraspSettings read_grasp_settings(const Config& config);

}  // namespace sg::grasp
