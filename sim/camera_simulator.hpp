#pragma once

#include <memory>

#include "common/config.hpp"
#include "sim/camera_renderer.hpp"
#include "sim/gripper.hpp"
#include "sim/occlusion.hpp"
#include "sim/scenario.hpp"
#include "sim/stereo_rig.hpp"

namespace sg::sim {

/// Lighting that changes over time: a global exposure gain and a slow drift of the colour
/// balance, both sinusoidal.
struct LightingParams {
  double gain_amplitude = 0.10;    ///< gain = 1 + amplitude * sin(2 pi t / period)
  double gain_period = 30.0;       ///< s
  double colour_amplitude = 0.03;  ///< per channel, phases 120 degrees apart
  double colour_period = 45.0;     ///< s
};

/// Everything the camera simulator needs; `load_sim_params` reads it from a Config (sections
/// rig, scenario, occlusion, lighting, camera_sim; every key range-checked, unknown keys refused).
struct SimParams {
  RigParams rig;
  ScenarioParams scenario;
  OcclusionParams occlusion;
  LightingParams lighting;
  StaticSceneParams scene;
  double ball_radius = 0.035;  ///< m
  double noise_sigma = 2.0;    ///< sensor noise, grey levels (standard deviation)
  double exposure = 0.0;       ///< s; > 0 with motion_blur_samples > 1 blurs the ball
  int motion_blur_samples = 1;
  double frame_rate = 30.0;      ///< Hz
  double max_lag = 0.2;          ///< s: real time, a frame later than this is dropped (FramePacing)
  double min_visible_px = 10.0;  ///< a camera "sees" the ball when this much of it shows
  std::string encoding = "jpeg";  ///< image_t encoding sg-camera-sim publishes: jpeg or raw
};

/// One rendered stereo pair and the truth behind it.
struct StereoFrame {
  int64_t index = 0;             ///< frame number from the start of the run
  double time = 0.0;             ///< scenario time of the capture, index / frame_rate (s)
  std::array<cv::Mat, 2> image;  ///< [0] left, [1] right; CV_8UC3 BGR
  Eigen::Vector3d ball = Eigen::Vector3d::Zero();  ///< the ball's true centre, robot frame (m)
  std::array<BallVisibility, 2> visibility;
  std::array<bool, 2> seen{false, false};  ///< visibility >= min_visible_px
};

/// The stereo camera simulator's pure core: frame index and arm state in, images and truth out.
/// No clock, no bus: the same parameters, seed and inputs give the same bytes.
///
///     sg::sim::CameraSimulator sim(sg::sim::load_sim_params(config));
///     sg::sim::StereoFrame frame;
///     sim.render(k, arm, frame);   // frame.image[0], frame.image[1], frame.ball, frame.seen
///
/// The ball follows the scenario, except once the gripper holds it: then it follows the tool
/// centre point, and where the gripper lets go it stays.
class CameraSimulator {
 public:
  explicit CameraSimulator(const SimParams& params);

  /// Renders frame `index` (scenario time index / frame_rate) with the arm as given.
  void render(int64_t index, const ArmState& arm, StereoFrame& frame);

  /// Where the ball is at frame `index` with this arm state (updates the carried/dropped state).
  Eigen::Vector3d ball_position(int64_t index, const ArmState& arm);

  const vision::CameraModel& camera(int i) const {
    return renderers_[static_cast<size_t>(i)]->camera();
  }
  const CameraRenderer& renderer(int i) const { return *renderers_[static_cast<size_t>(i)]; }
  const SimParams& params() const { return params_; }

 private:
  DynamicScene dynamic_scene(double t, const Eigen::Vector3d& ball, const ArmState& arm,
                             int64_t index) const;

  SimParams params_;
  std::unique_ptr<Scenario> scenario_;
  std::array<std::unique_ptr<CameraRenderer>, 2> renderers_;
  Eigen::Vector3d viewpoint_;
  bool carried_ = false;
  std::optional<Eigen::Vector3d> dropped_at_;
};

/// Reads SimParams from the `camera_sim`, `rig`, `scenario`, `occlusion` and `lighting` sections
/// (every key optional; defaults as above); throws ConfigError naming a bad key.
SimParams load_sim_params(const Config& config);

}  // namespace sg::sim
