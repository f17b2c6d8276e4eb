#include "sim/camera_simulator.hpp"

#include <cmath>
#include <stdexcept>

namespace sg::sim {

CameraSimulator::CameraSimulator(const SimParams& params)
    : params_(params), scenario_(make_scenario(params.scenario)) {
  if (!(params.frame_rate > 0)) throw std::invalid_argument("frame_rate must be positive");
  const auto cameras = make_rig(params.rig);
  for (int i = 0; i < 2; ++i) {
    StaticSceneParams scene = params.scene;
    renderers_[static_cast<size_t>(i)] = std::make_unique<CameraRenderer>(
        cameras[static_cast<size_t>(i)], scene, params.noise_sigma);
  }
  viewpoint_ = (cameras[0].centre() + cameras[1].centre()) / 2;
}

Eigen::Vector3d CameraSimulator::ball_position(int64_t index, const ArmState& arm) {
  if (arm.present && arm.holding_object) {
    carried_ = true;
    dropped_at_.reset();
    return arm.tool_position;
  }
  if (carried_) {  // just let go: the ball stays where the gripper opened
    carried_ = false;
    dropped_at_ = arm.tool_position;
  }
  if (dropped_at_) return *dropped_at_;
  return scenario_->position(static_cast<double>(index) / params_.frame_rate);
}

DynamicScene CameraSimulator::dynamic_scene(double t, const Eigen::Vector3d& ball,
                                            const ArmState& arm, int64_t index) const {
  DynamicScene scene;
  scene.ball_radius = params_.ball_radius;
  scene.ball_material.albedo = {0.10, 0.12, 0.80};
  scene.ball_material.specular = 0.5;
  const bool blur =
      params_.exposure > 0 && params_.motion_blur_samples > 1 && !carried_ && !dropped_at_;
  if (blur) {
    for (int s = 0; s < params_.motion_blur_samples; ++s) {
      const double dt = params_.exposure * (s / (params_.motion_blur_samples - 1.0) - 0.5);
      scene.ball_centres.push_back(scenario_->position(t + dt));
    }
  } else {
    scene.ball_centres.push_back(ball);
  }
  scene.boxes = gripper_boxes(arm);
  scene.panel = occluder_at(params_.occlusion, t, ball, viewpoint_);
  const LightingParams& l = params_.lighting;
  scene.gain = 1.0 + l.gain_amplitude * std::sin(2 * M_PI * t / l.gain_period);
  for (int c = 0; c < 3; ++c) {
    scene.colour_gain[c] =
        1.0 + l.colour_amplitude * std::sin(2 * M_PI * t / l.colour_period + c * 2 * M_PI / 3);
  }
  scene.noise_frame = index;
  return scene;
}

void CameraSimulator::render(int64_t index, const ArmState& arm, StereoFrame& frame) {
  frame.index = index;
  frame.time = static_cast<double>(index) / params_.frame_rate;
  frame.ball = ball_position(index, arm);
  DynamicScene scene = dynamic_scene(frame.time, frame.ball, arm, index);  // both cameras see it
  for (size_t i = 0; i < 2; ++i) {
    scene.noise_frame = index * 2 + static_cast<int64_t>(i);  // each its own sensor noise
    frame.visibility[i] = renderers_[i]->render(scene, frame.image[i]);
    frame.seen[i] = frame.visibility[i].visible_px >= params_.min_visible_px;
  }
}

namespace {

constexpr double kDeg = M_PI / 180;

void vector3(Section& section, const std::string& key, Eigen::Vector3d& v, const Range& range,
             const std::string& help) {
  section.numbers(key, v.data(), 3, range, help);
}

/// A value kept in radians, read in degrees.
void degrees(Section& section, const std::string& key, double& radians, const Range& range,
             const std::string& help) {
  double deg = radians / kDeg;
  section.number(key, deg, range, help);
  radians = deg * kDeg;
}

void read_rig(const Config& config, RigParams& r) {
  Section c(config, "rig");
  vector3(c, "target", r.target, Range::closed(-10, 10),
          "where the optical axes meet, robot frame (m)");
  c.number("baseline", r.baseline, Range::above_to(0, 10), "m between the camera centres");
  degrees(c, "toe_in_deg", r.toe_in, Range::above_to(0, 89.9), "each camera turned inward");
  degrees(c, "pitch_deg", r.pitch, Range::closed(-90, 90), "the rig's elevation over the target");
  degrees(c, "azimuth_deg", r.azimuth, Range::closed(-360, 360),
          "direction from the target to the rig (0: from +X)");
  c.number("width", r.width, Range::closed(16, 16384), "image width (px)");
  c.number("height", r.height, Range::closed(16, 16384), "image height (px)");
  c.number("fx", r.intrinsics.fx, Range::above_to(0, 1e5), "focal length (px)");
  c.number("fy", r.intrinsics.fy, Range::above_to(0, 1e5), "focal length (px)");
  r.intrinsics.cx = (r.width - 1) / 2.0;  // the image centre unless given
  r.intrinsics.cy = (r.height - 1) / 2.0;
  c.number("cx", r.intrinsics.cx, Range::closed(-1e5, 1e5), "principal point (px)");
  c.number("cy", r.intrinsics.cy, Range::closed(-1e5, 1e5), "principal point (px)");
  double d[5] = {r.distortion.k1, r.distortion.k2, r.distortion.p1, r.distortion.p2,
                 r.distortion.k3};
  c.numbers("distortion", d, 5, Range::closed(-100, 100), "k1 k2 p1 p2 k3 (OpenCV's model)");
  r.distortion = {d[0], d[1], d[2], d[3], d[4]};
  c.done();
}

void read_scenario(const Config& config, ScenarioParams& s) {
  Section c(config, "scenario");
  c.choice("kind", s.kind, scenario_kinds(), "how the ball moves");
  vector3(c, "centre", s.centre, Range::closed(-10, 10), "m, robot frame");
  c.number("radius", s.radius, Range::closed(0, 10), "m (paper, circle, figure8)");
  c.number("rpm", s.rpm, Range::closed(-600, 600), "revolutions per minute");
  degrees(c, "phase_deg", s.phase, Range::closed(-360, 360),
          "the starting phase (default: from the seed)");
  c.number("drift_speed", s.drift_speed, Range::closed(0, 10),
           "paper: back-and-forth along Y (m/s)");
  c.number("drift_half_period", s.drift_half_period, Range::above_to(0, 86400),
           "s between the drift's reversals");
  vector3(c, "line_direction", s.line_direction, Range::closed(-1e3, 1e3), "line: its direction");
  c.number("line_half_length", s.line_half_length, Range::above_to(0, 10), "line: m each way");
  c.number("line_speed", s.line_speed, Range::above_to(0, 10), "line: m/s");
  c.number("random_extent", s.random_extent, Range::above_to(0, 10), "random: m from the centre");
  c.number("random_speed", s.random_speed, Range::above_to(0, 10), "random: m/s");
  int64_t seed = static_cast<int64_t>(s.seed);
  c.number("seed", seed, Range::closed(0, 4294967295.0), "the starting phase, noise, distractors");
  s.seed = static_cast<uint64_t>(seed);
  c.done();
  try {
    make_scenario(s);
  } catch (const std::invalid_argument& e) {
    throw c.error("kind", e.what());
  }
}

void read_occlusion(const Config& config, OcclusionParams& o) {
  Section c(config, "occlusion");
  std::vector<std::vector<double>> episodes;
  if (c.read("episodes", episodes, "[]", "[start_s, duration_s] pairs", 0)) {
    for (const auto& e : episodes) {
      if (e.size() != 2 || !Range::closed(0, 86400).contains(e[0]) ||
          !Range::closed(0, 3600).contains(e[1]))
        throw c.error("episodes",
                      "must be a list of [start_s, duration_s] pairs, start_s in [0, 86400], "
                      "duration_s in [0, 3600]");
      o.episodes.push_back({e[0], e[1]});
    }
  }
  c.number("transition", o.transition, Range::closed(0, 60), "s to slide in and out");
  c.number("standoff", o.standoff, Range::above_to(0, 10), "panel distance from the ball (m)");
  c.number("width", o.width, Range::above_to(0, 10), "panel width (m)");
  c.number("height", o.height, Range::above_to(0, 10), "panel height (m)");
  c.done();
}

void read_lighting(const Config& config, LightingParams& l) {
  Section c(config, "lighting");
  c.number("gain_amplitude", l.gain_amplitude, Range::closed(0, 1), "exposure gain 1 +- this");
  c.number("gain_period", l.gain_period, Range::above_to(0, 86400), "s");
  c.number("colour_amplitude", l.colour_amplitude, Range::closed(0, 1),
           "colour balance drift per channel");
  c.number("colour_period", l.colour_period, Range::above_to(0, 86400), "s");
  c.done();
}

void read_camera_sim(const Config& config, SimParams& p) {
  Section c(config, "camera_sim");
  c.number("rate_hz", p.frame_rate, Range::above_to(0, 1000), "frames per second");
  c.number("max_lag", p.max_lag, Range::closed(0, 3600),
           "s: real time, frames later than this are dropped (0: never)");
  c.choice("encoding", p.encoding, {"jpeg", "raw"}, "image_t encoding on the bus");
  c.number("ball_radius", p.ball_radius, Range::above_to(0, 1), "m");
  c.number("noise_sigma", p.noise_sigma, Range::closed(0, 255), "sensor noise, grey levels");
  c.number("distractors", p.scene.distractors, Range::closed(0, 1000),
           "small red stickers of the ball's hue");
  c.number("exposure", p.exposure, Range::closed(0, 1), "s; blurs the moving ball");
  c.number("motion_blur_samples", p.motion_blur_samples, Range::closed(1, 64),
           "renders averaged over the exposure");
  c.number("min_visible_px", p.min_visible_px, Range::closed(0, 1e8),
           "a camera sees the ball above this area (px)");
  c.done();
}

}  // namespace

SimParams load_sim_params(const Config& c) {
  SimParams p;
  read_rig(c, p.rig);
  read_scenario(c, p.scenario);
  read_occlusion(c, p.occlusion);
  read_lighting(c, p.lighting);
  read_camera_sim(c, p);
  p.scene.seed = p.scenario.seed;
  return p;
}

}  // namespace sg::sim
