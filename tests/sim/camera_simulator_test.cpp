// The simulator over time: occlusions as configured, the carried ball, lighting, configuration.

#include "sim/camera_simulator.hpp"

#include <gtest/gtest.h>

namespace sg::sim {
namespace {

// At 4 Hz, an occlusion from 5 s lasting 2 s hides the ball from both cameras for exactly those
// frames; the panel slides in and out over the transition, and the ball is whole elsewhere.
TEST(CameraSimulator, OcclusionStartAndLengthAsConfigured) {
  SimParams p;
  p.frame_rate = 4;
  p.occlusion.episodes = {{5.0, 2.0}};
  p.occlusion.transition = 1.0;
  CameraSimulator sim(p);
  StereoFrame f;
  double last_visible = 1e9;
  bool partial = false;
  for (int64_t k = 0; k <= 40; ++k) {
    sim.render(k, {}, f);
    const double t = f.time;
    for (int i = 0; i < 2; ++i) {
      const BallVisibility& v = f.visibility[static_cast<size_t>(i)];
      if (t >= 5.0 && t <= 7.0) {
        EXPECT_LT(v.visible_px, 1.0) << "t " << t << " camera " << i;
        EXPECT_FALSE(f.seen[static_cast<size_t>(i)]) << t;
      } else if (t < 4.0 || t > 8.0) {
        EXPECT_NEAR(v.visible_px, v.silhouette_px, 1e-6) << t;
        EXPECT_TRUE(f.seen[static_cast<size_t>(i)]) << t;
      }
      if (v.visible_px > 1.0 && v.visible_px < v.silhouette_px - 1.0) partial = true;
    }
    if (t > 4.0 && t <= 5.0) {  // sliding in: never more of the ball than a frame before
      EXPECT_LE(f.visibility[0].visible_px, last_visible + 1e-6) << t;
      last_visible = f.visibility[0].visible_px;
    }
    EXPECT_EQ(fully_occluded_at(p.occlusion, t), t >= 5.0 && t <= 7.0);
  }
  EXPECT_TRUE(partial) << "the slide shows a partial occlusion";
}

// Held by the gripper the ball follows the tool centre point; let go, it stays there.
TEST(CameraSimulator, CarriedBallFollowsTheGripper) {
  CameraSimulator sim(SimParams{});
  ArmState arm;
  arm.present = true;
  arm.tool_rpy = {0, M_PI, 0};
  arm.holding_object = true;
  StereoFrame f;
  for (int64_t k = 0; k < 5; ++k) {
    arm.tool_position = Eigen::Vector3d(0.40 + 0.02 * k, -0.05, 0.20 + 0.01 * k);
    sim.render(k, arm, f);
    EXPECT_EQ(f.ball, arm.tool_position);
    EXPECT_TRUE(f.seen[0] && f.seen[1]);
  }
  const Eigen::Vector3d released = arm.tool_position;
  arm.holding_object = false;
  arm.tool_position += Eigen::Vector3d(0, 0, 0.1);  // the gripper rises and opens
  sim.render(5, arm, f);
  EXPECT_EQ(f.ball, Eigen::Vector3d(released.x(), released.y(), released.z() + 0.1));
  sim.render(6, arm, f);
  EXPECT_EQ(f.ball, Eigen::Vector3d(released.x(), released.y(), released.z() + 0.1));
}

// The exposure gain follows its sinusoid: brighter at its peak than at its trough.
TEST(CameraSimulator, LightingGainChangesBrightness) {
  SimParams p;
  p.noise_sigma = 0;
  p.lighting.gain_amplitude = 0.25;
  p.lighting.gain_period = 40;
  p.lighting.colour_amplitude = 0;
  p.frame_rate = 1;
  CameraSimulator sim(p);
  StereoFrame peak, trough;
  sim.render(10, {}, peak);    // gain 1.25
  sim.render(30, {}, trough);  // gain 0.75
  const double ratio = cv::mean(peak.image[0])[1] / cv::mean(trough.image[0])[1];
  EXPECT_GT(ratio, 1.5);
  EXPECT_LT(ratio, 1.25 / 0.75 + 0.02);
}

// Configuration errors name the key.
TEST(CameraSimulator, ConfigErrorsNameTheKey) {
  try {
    load_sim_params(Config::parse("rig:\n  baseline: -0.5\n", "lab.yaml"));
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("rig.baseline"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_sim_params(Config::parse("scenario:\n  kind: spiral\n", "lab.yaml")),
               ConfigError);
  EXPECT_THROW(load_sim_params(Config::parse("occlusion:\n  episodes: [[1, 2, 3]]\n", "lab.yaml")),
               ConfigError);
  const SimParams p = load_sim_params(
      Config::parse("scenario:\n  kind: figure8\nocclusion:\n  episodes: [[3, 4]]\n", "lab.yaml"));
  EXPECT_EQ(p.scenario.kind, "figure8");
  ASSERT_EQ(p.occlusion.episodes.size(), 1u);
  EXPECT_DOUBLE_EQ(p.occlusion.episodes[0].duration, 4.0);
}

}  // namespace
}  // namespace sg::sim

namespace sg::sim {
namespace {

// config/stereograsp.yaml loads and says what the built-in defaults are.
TEST(CameraSimulator, ShippedConfigMatchesDefaults) {
  const SimParams shipped =
      load_sim_params(Config::load(std::string(SG_SOURCE_DIR) + "/config/stereograsp.yaml"));
  const SimParams defaults;
  EXPECT_EQ(shipped.rig.target, defaults.rig.target);
  EXPECT_DOUBLE_EQ(shipped.rig.baseline, defaults.rig.baseline);
  EXPECT_NEAR(shipped.rig.toe_in, defaults.rig.toe_in, 1e-12);
  EXPECT_NEAR(shipped.rig.pitch, defaults.rig.pitch, 1e-12);
  EXPECT_DOUBLE_EQ(shipped.rig.intrinsics.fx, defaults.rig.intrinsics.fx);
  EXPECT_DOUBLE_EQ(shipped.rig.intrinsics.cx, defaults.rig.intrinsics.cx);
  EXPECT_EQ(shipped.scenario.kind, defaults.scenario.kind);
  EXPECT_DOUBLE_EQ(shipped.scenario.radius, defaults.scenario.radius);
  EXPECT_DOUBLE_EQ(shipped.scenario.drift_speed, defaults.scenario.drift_speed);
  EXPECT_DOUBLE_EQ(shipped.lighting.gain_amplitude, defaults.lighting.gain_amplitude);
  EXPECT_DOUBLE_EQ(shipped.frame_rate, defaults.frame_rate);
  EXPECT_DOUBLE_EQ(shipped.noise_sigma, defaults.noise_sigma);
  EXPECT_EQ(shipped.scene.distractors, defaults.scene.distractors);
  EXPECT_TRUE(shipped.occlusion.episodes.empty());
}

}  // namespace
}  // namespace sg::sim
