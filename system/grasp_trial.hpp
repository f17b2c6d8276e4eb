#pragma once

/// One grasp trial in simulated time, in-process, through the same library code as the live
/// system (issue 8): rendered stereo frames (CameraSimulator), the vision library behind
/// sg-vision (BlobTracker per camera, triangulate() with the true calibration), the predictor
/// behind sg-predictor (TrajectoryPredictor at 4 Hz), the grasp state machine behind sg-grasp
/// (grasp::GraspMachine) and the C550 controller model (C550Controller) behind a model of
/// sg-arm-driver's timing (docs/arm.md): a request is validated (arm::CommandValidator), waits in
/// a latest-wins slot while an interaction is in flight, and each motion command (MA, READY,
/// OPEN, CLOSE) executes one interaction_delay() after it is sent; the machine sees ARM_STATUS
/// at 20 Hz and when an interaction ends, with the joints read by W2.
///
///     sg::system::TrialParams params = sg::system::paper_trial(/*seed=*/7);
///     params.sim.scenario.rpm = 1.5;
///     params.render = false;             // truth + Gaussian noise instead of images + vision
///     sg::system::TrialResult r = sg::system::run_grasp_trial(params);
///     if (r.closed) std::printf("miss %.1f mm, held: %d\n", r.miss_distance * 1e3, r.success);
///
/// Times inside a trial are seconds from its start; the machine, the predictor and the
/// messages see microseconds since a fake epoch (kTrialEpochUtime) plus that time. A trial is a
/// pure function of its parameters: the same TrialParams give the same TrialResult.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "grasp/grasp_machine.hpp"
#include "predictor/trajectory_predictor.hpp"
#include "sim/c550_controller.hpp"
#include "sim/camera_simulator.hpp"
#include "vision/blob_tracker.hpp"

namespace sg::system {

using sim::C550Params;
using sim::SimParams;

/// The fake epoch of a trial's clock, microseconds (2023-11-14).
inline constexpr int64_t kTrialEpochUtime = 1'700'000'000'000'000;

/// Everything a trial depends on. paper_trial() fills it for the paper's scenario.
struct TrialParams {
  uint64_t seed = 1;             ///< seeds the camera noise, the C550 delays and the vision noise
  SimParams sim;                 ///< rig, scenario, occlusion episodes, lighting, noise
  bool render = true;            ///< false: no images; truth + Gaussian noise (vision_sigma)
  double frame_rate = 4.0;       ///< Hz: stereo frames (rendered + vision, or truth + noise)
  double vision_sigma = 0.0004;  ///< m per axis, !render: rendered vision measured 0.7 mm 3D RMS
  vision::BlobTracker::Params tracker;
  predictor::PredictorParams predictor;
  arm::ArmGeometry arm = arm::ArmGeometry::a465();
  C550Params c550;
  grasp::GraspSettings grasp;    ///< use_prediction = false is the --no-prediction baseline
  double status_rate = 20.0;   ///< Hz: ARM_STATUS between interactions
  double w2_time = 0.005;      ///< s: the W2 that ends an interaction (and an ABORT's answer)
  double bus_latency = 0.001;  ///< s: an ARM_STATUS sent on a change reaches the machine later
  double grasp_time = 45.0;    ///< s: the grasp command (track is commanded at 0)
  double timeout = 15.0;       ///< s after the grasp command: the trial ends without an outcome
  double settle_after_outcome = 0.0;  ///< s the trial runs on after the machine's outcome
};

/// The paper's scenario (config/stereograsp.yaml): a 0.15 m circle centred (0.45, 0, 0.10) at
/// 1 rpm, drift 0.01 m/s along Y reversing every 20 s, phase drawn from `seed`, no occlusion,
/// rendering on, grasp at 45 s (midway between the drift's reversals at 30 and 50 s).
TrialParams paper_trial(uint64_t seed);

/// What happened.
struct TrialResult {
  bool success = false;          ///< truth: the controller holds the ball after the lift executed
  bool machine_success = false;  ///< the machine's own judgement (outcome == kSuccess)
  bool machine_agrees = false;   ///< machine_success == success
  bool refused = false;          ///< the grasp command was refused (no grasp started)
  bool closed = false;           ///< a CLOSE executed
  bool lifted = false;           ///< the lift (a motion after the CLOSE) executed
  double miss_distance = std::nan("");  ///< m: TCP to the true ball centre at the CLOSE
  double close_time = std::nan("");     ///< s: when the CLOSE executed
  double grasp_time = 0;                ///< s: the grasp command
  /// Diagnostics of the approach (a1 + a2): its target (the TCP aim) against the true ball at
  /// the close, and the machine's intended close time T against the actual one.
  double aim_error = std::nan("");     ///< m: |approach target - true ball at the close|
  double timing_error = std::nan("");  ///< s: actual close - target_utime
  double track_age = std::nan("");     ///< s: close time - last visible measurement before it
  double end_time = 0;                 ///< s: when the trial stopped
  grasp::GraspOutcome outcome = grasp::GraspOutcome::kNone;
  grasp::GraspState final_state = grasp::GraspState::kHandOpened;
  std::string message;               ///< the machine's last status message
  std::string arm_rejection;         ///< the last reason the driver model or controller refused
  int frames = 0;                    ///< stereo frames (or truth samples)
  int visible = 0;                   ///< of which the ball was measured in both cameras
  int trajectories = 0;              ///< forecasts given to the machine
  int requests = 0;                  ///< ArmRequests taken from the machine
  int rejected = 0;                  ///< of which refused (validator or controller)
  int interactions = 0;              ///< controller interactions
  double vision_rms = std::nan("");  ///< m: 3D RMS of the measurements against the truth
                                     ///< (visible frames, ball not carried)
};

/// Runs one trial. Throws std::invalid_argument for bad parameters (a scenario or controller
/// parameter out of range, a non-positive rate).
TrialResult run_grasp_trial(const TrialParams& params);

}  // namespace sg::system
