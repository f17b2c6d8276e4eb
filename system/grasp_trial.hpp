#pragma once

/// One grasp trial in simulated time, in one process, composed of the product's own parts on one
/// SimulatedClock (DESIGN rule 8): the simulated world (sim::CameraSimulator renders both
/// cameras, sim::C550Controller is the arm) on one side, and on the other what the lab runs —
/// vision::StereoStep (sg-vision's stereo step), predictor::TrajectoryPredictor with its
/// OBJECT_TRAJECTORY message (sg-predictor), grasp::GraspNode (sg-grasp) and arm::ArmDriver
/// (sg-arm-driver's core), which speaks RAPL-II and ACI bytes through a SimulatedLine to the
/// C550 emulator exactly as it does through sg-c550-sim's pseudo-terminal. Messages between the
/// processes are encoded and decoded as on the bus and arrive `bus_latency` later. The trial
/// holds no rule of its own: a change to the driver's speed clamp, the visibility rule, the
/// forecast's message or the machine reaches its result.
///
///     sg::system::TrialParams params = sg::system::paper_trial(/*seed=*/7);
///     params.sim.scenario.rpm = 1.5;
///     params.render = false;   // a model of the camera: projected truth + pixel noise
///     sg::system::TrialResult r = sg::system::run_grasp_trial(params);
///     if (r.closed) std::printf("miss %.1f mm, held: %d\n", r.miss_distance * 1e3, r.success);
///
/// Times inside a trial are seconds from its start; messages carry microseconds since a fake
/// epoch (kTrialEpochUtime) plus that time. A trial is a pure function of its parameters: the
/// same TrialParams give the same TrialResult.
///
/// With `render = false` the camera and the blob tracker are replaced by a labelled model: the
/// true centre projected into each camera plus Gaussian pixel noise, seen unless an occlusion
/// episode hides it fully; the product's own position_of() (visibility rule, triangulation)
/// still turns those into OBJECT_POSITION.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "arm_driver/arm_driver.hpp"
#include "grasp/grasp_machine.hpp"
#include "predictor/trajectory_predictor.hpp"
#include "sim/c550_controller.hpp"
#include "sim/camera_simulator.hpp"
#include "vision/blob_tracker.hpp"
#include "vision/calibration_file.hpp"

namespace sg::system {

/// The fake epoch of a trial's clock, microseconds (2023-11-14).
inline constexpr int64_t kTrialEpochUtime = 1'700'000'000'000'000;

/// Everything a trial depends on. paper_trial() fills it for the paper's scenario.
struct TrialParams {
  uint64_t seed = 1;          ///< seeds the camera noise, the C550 delays and the pixel noise
  sim::SimParams sim;         ///< rig, scenario, occlusion episodes, lighting, noise
  bool render = true;         ///< false: no images; the camera model above
  double frame_rate = 4.0;    ///< Hz: stereo frames
  double pixel_sigma = 0.25;  ///< px per axis, !render (rendered vision measured ~0.7 mm 3D RMS)
  vision::BlobTracker::Params tracker;
  /// The cameras sg-vision triangulates with (e.g. calibration_trial.hpp's robot-guided one);
  /// unset: the simulator's true cameras.
  std::optional<vision::StereoCalibration> calibration;
  predictor::PredictorParams predictor;
  arm::ArmGeometry arm = arm::ArmGeometry::a465();
  sim::C550Params c550;
  arm::DriverSettings driver;      ///< sg-arm-driver's settings (timing, polls, retries)
  int baud = 38400;                ///< the serial line
  grasp::GraspSettings grasp;      ///< use_prediction = false is the --no-prediction baseline
  double arm_status_rate = 20.0;   ///< Hz: sg-arm-driver's ARM_STATUS at rest
  double grasp_status_rate = 4.0;  ///< Hz: sg-grasp's GRASP_STATUS at rest
  double bus_latency = 0.001;      ///< s: a message reaches its subscribers this much later
  double grasp_time = 45.0;        ///< s: the grasp command (track is commanded at 0)
  double timeout = 15.0;           ///< s after the grasp command: the trial ends without an outcome
  double settle_after_outcome = 0.0;  ///< s the trial runs on after the machine's outcome
};

/// The paper's scenario (config/stereograsp.yaml): a 0.15 m circle centred (0.45, 0, 0.10) at
/// 1 rpm, drift 0.01 m/s along Y reversing every 20 s, phase drawn from `seed`, no occlusion,
/// rendering on, grasp at 45 s (midway between the drift's reversals at 30 and 50 s).
TrialParams paper_trial(uint64_t seed);

/// What happened.
struct TrialResult {
  bool success = false;          ///< truth: the controller holds the ball, lifted above the close
  bool machine_success = false;  ///< the machine's own judgement (outcome == kSuccess)
  bool machine_agrees = false;   ///< machine_success == success
  bool refused = false;          ///< the grasp command was refused (no grasp started)
  bool closed = false;           ///< a CLOSE executed
  bool lifted = false;           ///< the tool rose half the lift height above the close, holding
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
  std::string approach_message;      ///< ... when it sent the approach that closes the hand
  std::string arm_rejection;         ///< the last reason the driver or controller refused
  int frames = 0;                    ///< stereo frames
  int visible = 0;                   ///< of which OBJECT_POSITION was visible
  int trajectories = 0;              ///< OBJECT_TRAJECTORY messages
  int requests = 0;                  ///< ARM_COMMAND messages
  int rejected = 0;                  ///< of which refused (driver's validator or controller)
  int interactions = 0;              ///< motion lines the controller received (MA, READY, ...)
  uint64_t serial_bytes = 0;         ///< bytes the driver wrote on the line
  int replans = 0;  ///< approaches the machine re-planned (a turn seen after one began)
  int gripper_actions_dropped = 0;  ///< CLOSEs that gave way to a newer command in the driver
  double vision_rms = std::nan("");  ///< m: 3D RMS of the measurements against the truth
  int64_t vision_samples = 0;        ///< visible measurements vision_rms is over
                                     ///< (visible frames, ball not carried)
};

/// Runs one trial. Throws std::invalid_argument for bad parameters (a scenario or controller
/// parameter out of range, a non-positive rate).
TrialResult run_grasp_trial(const TrialParams& params);

}  // namespace sg::system
