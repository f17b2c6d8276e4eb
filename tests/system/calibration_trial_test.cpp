#include "system/calibration_trial.hpp"

#include <gtest/gtest.h>

#include "sim/stereo_rig.hpp"

namespace sg::system {
namespace {

/// sg-calibrate's default grid (18 stops) in the paper's lab, rendered at 10 Hz.
CalibrationTrialParams default_grid() { return calibration_trial_for(paper_trial(5)); }

// The robot-guided calibration, run through the driver, the C550 emulator, the rendered cameras
// and the tracker, recovers the simulator's true cameras: at most 4 of 18 stops left out where
// the gripper hides the ball from one camera (the upper layer's corners; 4 here, the process
// test allows 3 at 30 Hz), the ball's offset on the tool (zero:
// the emulator holds it at the tool centre point) within 2 mm, and points of the box
// triangulated within 1 mm RMS (the process test's bound; 0.31 mm measured here).
TEST(CalibrationTrial, RecoversTheTrueCameras) {
  const CalibrationTrialResult r = run_calibration_trial(default_grid());
  EXPECT_EQ(r.stops, 18);
  EXPECT_LE(r.skipped, 4);
  EXPECT_LT(r.solution.ball_offset.norm(), 0.002);
  EXPECT_LT(r.triangulation_rms, 0.001);
  EXPECT_LT(r.solution.cameras.rms_left, 1.0);
  EXPECT_LT(r.solution.cameras.rms_right, 1.0);
  // The arm took time to visit them: at least a controller interaction a stop.
  EXPECT_GT(r.duration, 18 * 0.72);
  // The true cameras' centres, recovered: the left camera's within 1 cm.
  const auto truth = sim::make_rig(default_grid().sim.rig);
  EXPECT_LT((r.solution.cameras.left.centre() - truth[0].centre()).norm(), 0.01);
}

// A grasp trial that triangulates with that calibration grasps the ball, like one with the
// simulator's own cameras.
TEST(CalibrationTrial, GraspTrialWithItHoldsTheBall) {
  TrialParams p = paper_trial(3);
  p.render = false;
  p.sim.scenario.phase = 0.7;
  p.grasp_time = 42.0;
  p.sim.occlusion.episodes = {{41.0, 3.5}};
  p.timeout = 10.0;
  p.calibration = run_calibration_trial(default_grid()).solution.cameras;
  const TrialResult r = run_grasp_trial(p);
  EXPECT_TRUE(r.success) << r.message << " miss " << r.miss_distance;
  EXPECT_LT(r.miss_distance, 0.02);
}

// Parameters that cannot run are refused, naming what.
TEST(CalibrationTrial, BadParametersAreRefused) {
  CalibrationTrialParams c = default_grid();
  c.frame_rate = 0;
  EXPECT_THROW(run_calibration_trial(c), std::invalid_argument);
  c = default_grid();
  c.arm.status_rate = -1;
  EXPECT_THROW(run_calibration_trial(c), std::invalid_argument);
}

}  // namespace
}  // namespace sg::system
