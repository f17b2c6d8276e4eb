#pragma once

#include <string>

#include "common/config.hpp"
#include "predictor/position_gate.hpp"
#include "predictor/trajectory_predictor.hpp"

namespace sg::predictor {

/// What sg-predictor is configured with: the `predictor` section (docs/prediction.md).
struct PredictorSettings {
  PredictorParams params;
  std::string coefficients;  ///< an offline-trained coefficients file; "" = learn online
  PositionGateParams gate;   ///< what OBJECT_POSITION must be to reach the predictor
  /// Where the trajectories go: OBJECT_TRAJECTORY, which sg-grasp follows, or another channel
  /// for a second predictor beside the first (a baseline model, or the same one on another host
  /// to time the path across hosts: scripts/lab_trial.sh --paired).
  std::string output_channel = "OBJECT_TRAJECTORY";
};

/// True when `name` can be a channel of this system's bus: 1 to 63 characters (LCM's limit) of
/// letters, digits, '_', '-' and '.'.
bool valid_channel_name(const std::string& name);

/// Reads the `predictor` section: every key range-checked, any other key of the section refused
/// with the nearest known one. Absent keys keep PredictorParams' defaults. The gate's box is the
/// arm's workspace, read from the `arm` section (arm::load_arm_geometry, its one definition).
PredictorSettings read_predictor_settings(const Config& config);

/// Reads a coefficients file that `sg-predictor train` wrote (order, coefficients.x/y/z) into
/// `params` (its order becomes the Burg order). Errors name the file, line and key.
void read_coefficients(const std::string& path, PredictorParams& params);

}  // namespace sg::predictor
