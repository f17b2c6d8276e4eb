#pragma once

/// Robot-guided calibration (the paper's section 4; vision/robot_calibration.hpp) in simulated
/// time, in one process, from the product's own parts as `sg-calibrate robot` runs them in the
/// lab: the C550 powers up with the ball in the gripper (sg-c550-sim --holding), sg-arm-driver's
/// core drives it over the simulated line (SimulatedArm), the simulated cameras render the ball
/// and the gripper at each stop, sg-vision's stereo step (without a calibration) publishes the
/// blobs, and vision::RobotCalibration commands the grid, averages the blobs and solves both
/// cameras and the ball's offset on the tool. Each ARM_COMMAND is signed, kept alive by
/// heartbeats every 0.2 s and the lease released at the end, as sg-calibrate's commander does.
///
///     sg::system::CalibrationTrialParams c = sg::system::calibration_trial_for(grasp_params);
///     sg::system::CalibrationTrialResult r = sg::system::run_calibration_trial(c);
///     grasp_params.calibration = r.solution.cameras;   // the grasp trials triangulate with it
///     std::printf("%.2f mm\n", r.triangulation_rms * 1e3);
///
/// A pure function of its parameters, like the grasp trial.

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/camera_simulator.hpp"
#include "system/grasp_trial.hpp"
#include "system/simulated_arm.hpp"
#include "vision/blob_tracker.hpp"
#include "vision/robot_calibration.hpp"

namespace sg::system {

struct CalibrationTrialParams {
  sim::SimParams sim;        ///< the rig, lighting, noise (the scenario's path is not used)
  double frame_rate = 10.0;  ///< Hz: stereo frames
  vision::BlobTracker::Params tracker;
  vision::RobotCalibrationParams calibration;  ///< the grid (ball_radius: sim.ball_radius)
  SimulatedArmParams arm;      ///< c550.start_holding is set: the ball starts in the gripper
  double bus_latency = 0.001;  ///< s
  /// s: when sg-camera-sim first hears SIM_ARM_STATE; before it, it draws the ball on its
  /// scenario path (in view), as it does in the lab's order of starting (scripts/demo.sh). The
  /// tracker meets the ball there first and learns its size; a tracker that starts with the ball
  /// out of view (the arm at READY) may lock on a red sticker instead (docs/grasping.md).
  double arm_heard_after = 1.0;
  /// s after that before sg-calibrate commands the first stop (it starts once the cameras film
  /// the ball in the gripper, as tests/integration/robot_calibration_test.cpp waits).
  double start_after = 1.0;
  double timeout = 900.0;  ///< s of simulated time before giving up (throws)
};

/// The calibration a grasp trial's lab would make: its rig, scene, arm, controller and tracker.
CalibrationTrialParams calibration_trial_for(const TrialParams& grasp);

struct CalibrationTrialResult {
  vision::HandEyeSolution solution;  ///< the cameras in the robot frame, the ball's offset
  std::vector<vision::CalibrationStop> stop_records;  ///< each stop and what was seen there
  int stops = 0;                                      ///< of the grid
  int skipped = 0;      ///< refused by the arm or not seen by both cameras
  double duration = 0;  ///< s of simulated time the procedure took
  /// m: RMS distance between points of the calibration box (a 5 x 5 x 5 grid) and their
  /// triangulation (eq. 23-26) by the calibrated cameras from their exact projections in the
  /// simulator's true cameras: the calibration's own 3D error, without the tracker's.
  double triangulation_rms = std::nan("");
};

/// Runs the procedure. Throws std::runtime_error when it does not finish within `timeout` or
/// the solve has too few stops (vision::CalibrationInputError's message).
CalibrationTrialResult run_calibration_trial(const CalibrationTrialParams& params);

}  // namespace sg::system
