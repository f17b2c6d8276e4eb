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

Eigen::Vector3d vector3(const Config& c, const std::string& key, const Eigen::Vector3d& fallback) {
  if (!c.has(key)) return fallback;
  const auto v = c.require<std::vector<double>>(key);
  if (v.size() != 3) throw c.error_at(key, "must be a list of 3 numbers");
  return {v[0], v[1], v[2]};
}

double positive(const Config& c, const std::string& key, double fallback) {
  const double v = c.get<double>(key, fallback);
  if (!(v > 0) || !std::isfinite(v)) throw c.error_at(key, "must be a positive number");
  return v;
}

double non_negative(const Config& c, const std::string& key, double fallback) {
  const double v = c.get<double>(key, fallback);
  if (!(v >= 0) || !std::isfinite(v)) throw c.error_at(key, "must be a number >= 0");
  return v;
}

}  // namespace

SimParams load_sim_params(const Config& c) {
  SimParams p;
  constexpr double kDeg = M_PI / 180;
  RigParams& r = p.rig;
  r.target = vector3(c, "rig.target", r.target);
  r.baseline = positive(c, "rig.baseline", r.baseline);
  r.toe_in = positive(c, "rig.toe_in_deg", r.toe_in / kDeg) * kDeg;
  if (r.toe_in >= M_PI / 2) throw c.error_at("rig.toe_in_deg", "must be below 90");
  r.pitch = c.get<double>("rig.pitch_deg", r.pitch / kDeg) * kDeg;
  r.azimuth = c.get<double>("rig.azimuth_deg", r.azimuth / kDeg) * kDeg;
  r.width = static_cast<int>(positive(c, "rig.width", r.width));
  r.height = static_cast<int>(positive(c, "rig.height", r.height));
  r.intrinsics.fx = positive(c, "rig.fx", r.intrinsics.fx);
  r.intrinsics.fy = positive(c, "rig.fy", r.intrinsics.fy);
  r.intrinsics.cx = c.get<double>("rig.cx", (r.width - 1) / 2.0);
  r.intrinsics.cy = c.get<double>("rig.cy", (r.height - 1) / 2.0);
  if (c.has("rig.distortion")) {
    const auto d = c.require<std::vector<double>>("rig.distortion");
    if (d.size() != 5) throw c.error_at("rig.distortion", "must be 5 numbers: k1 k2 p1 p2 k3");
    r.distortion = {d[0], d[1], d[2], d[3], d[4]};
  }

  ScenarioParams& s = p.scenario;
  s.kind = c.get<std::string>("scenario.kind", s.kind);
  s.centre = vector3(c, "scenario.centre", s.centre);
  s.radius = non_negative(c, "scenario.radius", s.radius);
  s.rpm = c.get<double>("scenario.rpm", s.rpm);
  s.phase = c.has("scenario.phase_deg") ? c.require<double>("scenario.phase_deg") * kDeg : s.phase;
  s.drift_speed = non_negative(c, "scenario.drift_speed", s.drift_speed);
  s.drift_half_period = positive(c, "scenario.drift_half_period", s.drift_half_period);
  s.line_direction = vector3(c, "scenario.line_direction", s.line_direction);
  s.line_half_length = positive(c, "scenario.line_half_length", s.line_half_length);
  s.line_speed = positive(c, "scenario.line_speed", s.line_speed);
  s.random_extent = positive(c, "scenario.random_extent", s.random_extent);
  s.random_speed = positive(c, "scenario.random_speed", s.random_speed);
  s.seed = static_cast<uint64_t>(c.get<int64_t>("scenario.seed", static_cast<int64_t>(s.seed)));
  try {
    make_scenario(s);
  } catch (const std::invalid_argument& e) {
    throw c.error_at("scenario.kind", e.what());
  }

  OcclusionParams& o = p.occlusion;
  if (c.has("occlusion.episodes")) {
    const auto flat = c.require<std::vector<std::vector<double>>>("occlusion.episodes");
    for (const auto& e : flat) {
      if (e.size() != 2 || !(e[1] >= 0))
        throw c.error_at("occlusion.episodes", "must be a list of [start_s, duration_s] pairs");
      o.episodes.push_back({e[0], e[1]});
    }
  }
  o.transition = non_negative(c, "occlusion.transition", o.transition);
  o.standoff = positive(c, "occlusion.standoff", o.standoff);
  o.width = positive(c, "occlusion.width", o.width);
  o.height = positive(c, "occlusion.height", o.height);

  LightingParams& l = p.lighting;
  l.gain_amplitude = non_negative(c, "lighting.gain_amplitude", l.gain_amplitude);
  l.gain_period = positive(c, "lighting.gain_period", l.gain_period);
  l.colour_amplitude = non_negative(c, "lighting.colour_amplitude", l.colour_amplitude);
  l.colour_period = positive(c, "lighting.colour_period", l.colour_period);

  p.scene.distractors =
      static_cast<int>(non_negative(c, "camera_sim.distractors", p.scene.distractors));
  p.scene.seed = s.seed;
  p.ball_radius = positive(c, "camera_sim.ball_radius", p.ball_radius);
  p.noise_sigma = non_negative(c, "camera_sim.noise_sigma", p.noise_sigma);
  p.exposure = non_negative(c, "camera_sim.exposure", p.exposure);
  p.motion_blur_samples = static_cast<int>(positive(c, "camera_sim.motion_blur_samples", 1));
  p.frame_rate = positive(c, "camera_sim.rate_hz", p.frame_rate);
  p.min_visible_px = non_negative(c, "camera_sim.min_visible_px", p.min_visible_px);
  return p;
}

}  // namespace sg::sim
