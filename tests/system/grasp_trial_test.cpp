#include "system/grasp_trial.hpp"

#include <gtest/gtest.h>

namespace sg::system {
namespace {

/// The paper's ball at 1 rpm, no images (truth + noise), an occlusion over the grasp.
TrialParams quick_trial() {
  TrialParams p = paper_trial(3);
  p.render = false;
  p.sim.scenario.rpm = 1.0;
  p.sim.scenario.phase = 0.7;
  p.grasp_time = 42.0;  // 8 s away from the drift reversal at 50 s
  p.sim.occlusion.episodes = {{41.0, 3.5}};
  p.timeout = 10.0;
  return p;
}

// With prediction the arm holds the ball after the lift, and the machine judges it so too.
TEST(GraspTrial, PredictionGraspsTheBallAtOneRpm) {
  const TrialResult r = run_grasp_trial(quick_trial());
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.lifted);
  EXPECT_TRUE(r.success) << r.message << " miss " << r.miss_distance;
  EXPECT_LT(r.miss_distance, 0.02);
  EXPECT_EQ(r.outcome, grasp::GraspOutcome::kSuccess) << r.message;
  EXPECT_TRUE(r.machine_agrees);
  EXPECT_GT(r.close_time, r.grasp_time);
  EXPECT_EQ(r.final_state, grasp::GraspState::kObjectLifted);
}

// A ball beyond the arm's reach is never grasped: the machine refuses the targets and says why.
TEST(GraspTrial, BallOutOfReachIsRefused) {
  TrialParams p = quick_trial();
  p.sim.scenario.centre = {1.05, 0.0, 0.10};
  p.sim.scenario.radius = 0.05;
  p.sim.scenario.drift_speed = 0.0;
  p.sim.occlusion.episodes.clear();
  p.grasp_time = 20.0;
  p.timeout = 5.0;
  const TrialResult r = run_grasp_trial(p);
  EXPECT_FALSE(r.closed);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.outcome, grasp::GraspOutcome::kSuccess);
  EXPECT_NE(r.message.find("refused"), std::string::npos) << r.message;
  EXPECT_EQ(r.requests, 1);  // only a0, the open hand: no target was ever sent to the arm
  EXPECT_TRUE(r.machine_agrees);
}

// The same parameters (rendered frames and vision included) give the same result twice.
TEST(GraspTrial, SameSeedSameResult) {
  TrialParams p = quick_trial();
  p.render = true;
  p.grasp_time = 16.0;
  p.sim.occlusion.episodes = {{15.0, 3.0}};
  p.timeout = 6.0;
  const TrialResult a = run_grasp_trial(p);
  const TrialResult b = run_grasp_trial(p);
  EXPECT_GT(a.visible, 0);
  EXPECT_EQ(a.success, b.success);
  EXPECT_EQ(a.closed, b.closed);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.visible, b.visible);
  EXPECT_EQ(a.requests, b.requests);
  EXPECT_EQ(a.interactions, b.interactions);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.end_time, b.end_time);
  if (a.closed) {
    EXPECT_EQ(a.close_time, b.close_time);
    EXPECT_EQ(a.miss_distance, b.miss_distance);
  }
  EXPECT_EQ(a.vision_rms, b.vision_rms);
}

// The trial runs the product's driver: its speed cap (DriverSettings::max_speed, 5 % of the
// joints' speeds) slows the real arm model, and the grasp that held at full speed now misses.
TEST(GraspTrial, DriverSpeedCapReachesTheTrial) {
  const TrialResult full = run_grasp_trial(quick_trial());
  TrialParams p = quick_trial();
  p.driver.max_speed = 0.05;
  const TrialResult capped = run_grasp_trial(p);
  ASSERT_TRUE(full.success) << full.message;
  EXPECT_FALSE(capped.success) << capped.message;
  EXPECT_GT(capped.miss_distance, full.miss_distance);
}

// The trial runs the product's stereo step: a tracker that ignores regions under 10^6 px never
// finds the ball, OBJECT_POSITION is never visible, and sg-grasp refuses the grasp for want of a
// track.
TEST(GraspTrial, VisionRuleReachesTheTrial) {
  TrialParams p = quick_trial();
  p.render = true;
  p.grasp_time = 8.0;
  p.sim.occlusion.episodes.clear();
  p.timeout = 2.0;
  const TrialResult seen = run_grasp_trial(p);
  p.tracker.min_area = 1'000'000;
  const TrialResult blind = run_grasp_trial(p);
  EXPECT_GT(seen.visible, seen.frames / 2);
  EXPECT_FALSE(seen.refused) << seen.message;
  EXPECT_EQ(blind.visible, 0);
  EXPECT_TRUE(blind.refused) << blind.message;
}

// Every ARM_COMMAND crosses the real driver: the emulator received motion lines, and the bytes
// on the line are those of RAPL-II lines (an MA with six joints is some 50 characters).
TEST(GraspTrial, CommandsCrossTheSerialLine) {
  const TrialResult r = run_grasp_trial(quick_trial());
  EXPECT_GT(r.requests, 10);
  EXPECT_GT(r.interactions, 10);
  EXPECT_LE(r.interactions, r.requests + 2);  // latest wins: never more lines than commands
  EXPECT_GT(r.serial_bytes, 30u * static_cast<uint64_t>(r.interactions));
}

// A drift turn seen after the approach began (1.6 rpm, r = 0.112 m, closing at 48.8 s) is
// re-planned and held; the same draw without re-planning closes on the old forecast and misses.
TEST(GraspTrial, TurnAfterTheApproachIsReplannedAndHeld) {
  TrialParams p = quick_trial();
  p.sim.scenario.rpm = 1.6;
  p.sim.scenario.radius = 0.112;
  p.sim.scenario.drift_speed = 0.0099;
  p.sim.occlusion.episodes.clear();
  p.grasp_time = 48.8;
  const TrialResult replanned = run_grasp_trial(p);
  EXPECT_TRUE(replanned.success) << replanned.message;
  EXPECT_GE(replanned.replans, 1);
  EXPECT_GE(replanned.gripper_actions_dropped, 1);
  EXPECT_LT(replanned.miss_distance, 0.02);

  p.grasp.max_replans = 0;
  const TrialResult blind = run_grasp_trial(p);
  EXPECT_FALSE(blind.success);
  EXPECT_EQ(blind.replans, 0);
  EXPECT_GT(blind.miss_distance, 0.02);
}

}  // namespace
}  // namespace sg::system
