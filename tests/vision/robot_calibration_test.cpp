// The robot-guided calibration on message streams: an arm that reports each arrival, cameras that
// see the ball it carries; the result triangulates the workspace within 2 mm.

#include "vision/robot_calibration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "sim/stereo_rig.hpp"
#include "vision/sphere_image.hpp"
#include "vision/triangulation.hpp"

namespace sg::vision {
namespace {

constexpr double kBallRadius = 0.035;  // m, RobotCalibrationParams' default

/// Plays the arm and the cameras: the arm arrives 0.8 s (message time) after each command; the
/// cameras see the ball at 30 Hz with `noise` px of noise and miss it with probability `drop`.
/// The ball (radius 35 mm) sits at `offset` (tool frame) from the tool centre point; each blob
/// reports `fit_support` and `arc`, and the centre of the ball's image a tracker finds on those
/// sectors of its outline (the centroid of the ellipse for a whole disc), not the projection of
/// the ball's centre.
HandEyeSolution run_hand_eye(RobotCalibration& cal, double noise, double drop,
                             bool hide_first_stop = false,
                             const Eigen::Vector3d& offset = Eigen::Vector3d::Zero(),
                             double fit_support = std::nan(""), uint64_t arc = kWholeArc) {
  const auto rig = sim::make_rig({});
  std::mt19937 rng(17);
  std::normal_distribution<double> jitter(0, noise);
  std::uniform_real_distribution<double> unit(0, 1);
  int64_t utime = 1'700'000'000'000'000, executed = 0;
  Eigen::Vector3d ball = Eigen::Vector3d::Zero();
  int stop = 0;
  for (int guard = 0; !cal.done() && guard < 100000; ++guard) {
    if (auto target = cal.next_target()) {
      utime += 800'000;  // the controller's interaction time
      executed = target->sequence;
      const Eigen::Vector3d& rpy = target->rpy;  // R = Rz(yaw) Ry(pitch) Rx(roll)
      ball = target->position + (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX())) *
                                    offset;
      ++stop;
    }
    cal.on_arm_status(utime, executed, true);
    utime += 33'333;
    for (int c = 0; c < 2; ++c) {
      const bool hidden = (hide_first_stop && stop == 1) || unit(rng) < drop;
      const Eigen::Vector2d px =
          *sphere_outline_centre(rig[static_cast<size_t>(c)], ball, kBallRadius, arc) +
          Eigen::Vector2d(jitter(rng), jitter(rng));
      cal.on_blob(c, utime, !hidden, px, fit_support, 30, arc);
    }
  }
  EXPECT_TRUE(cal.done());
  return cal.solve_hand_eye();
}

/// Commands the first stop and reports the arm there at `utime`.
void arrive_at_first_stop(RobotCalibration& cal, int64_t utime) {
  const auto t = cal.next_target();
  ASSERT_TRUE(t);
  cal.on_arm_status(utime, t->sequence, true);
}

StereoCalibration run_procedure(RobotCalibration& cal, double noise, double drop,
                                bool hide_first_stop = false) {
  return run_hand_eye(cal, noise, drop, hide_first_stop).cameras;
}

/// RMS distance between points through the workspace and their triangulation from their true
/// pixels with `c`.
double triangulation_rms(const StereoCalibration& c) {
  const auto rig = sim::make_rig({});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(0.3, 0.6), y(-0.2, 0.2), z(0.05, 0.25);
  double sum = 0;
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d p(x(rng), y(rng), z(rng));
    sum += (triangulate({&c.left, &c.right}, {*rig[0].project(p), *rig[1].project(p)}).position - p)
               .squaredNorm();
  }
  return std::sqrt(sum / 100);
}

// 18 stops, 10 frames each, 0.3 px noise and 10% dropouts: mm-accurate cameras in the robot frame.
TEST(RobotCalibration, GridOfStopsGivesTheCamerasInTheRobotFrame) {
  RobotCalibration cal({});
  EXPECT_EQ(cal.stops().size(), 18u);
  EXPECT_NE(cal.progress().find("stop 1 of 18"), std::string::npos);
  const StereoCalibration c = run_procedure(cal, 0.3, 0.1);
  EXPECT_LT(triangulation_rms(c), 0.002);
  EXPECT_LT(c.rms_left, 0.5);
  for (const auto& s : cal.stops()) {
    EXPECT_EQ(s.frames[0], 10);
    EXPECT_FALSE(s.skipped);
  }
  std::printf("robot-guided calibration: RMS %.3f/%.3f px, 3D RMS %.3f mm\n", c.rms_left,
              c.rms_right, triangulation_rms(c) * 1e3);
}

// The procedure waits for the arm: no blob counts before it reports the commanded move done and
// the settling time has passed; one command per stop.
TEST(RobotCalibration, WaitsForArrivalAndSettling) {
  RobotCalibration cal({}, 100);
  const auto first = cal.next_target();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->sequence, 100);
  EXPECT_FALSE(cal.next_target()) << "one command per stop";
  cal.on_blob(0, 1'000'000, true, {1, 1});
  cal.on_arm_status(1'000'000, 99, true);  // an older command
  cal.on_blob(0, 1'100'000, true, {1, 1});
  cal.on_arm_status(2'000'000, 100, false);  // done but still moving
  cal.on_blob(0, 2'100'000, true, {1, 1});
  EXPECT_EQ(cal.stops()[0].frames[0], 0);
  cal.on_arm_status(3'000'000, 100, true);
  cal.on_blob(0, 3'100'000, true, {1, 1});  // within the 0.5 s settling
  EXPECT_EQ(cal.stops()[0].frames[0], 0);
  cal.on_blob(0, 3'600'000, true, {1, 1});
  EXPECT_EQ(cal.stops()[0].frames[0], 1);
  EXPECT_NE(cal.progress().find("collecting (left 1/10, right 0/10)"), std::string::npos)
      << cal.progress();
}

// A stop where the ball cannot be seen is skipped; too few usable stops is an error.
TEST(RobotCalibration, UnseenStopsAreSkippedAndTooFewFail) {
  RobotCalibration cal({});
  const StereoCalibration c = run_procedure(cal, 0.2, 0.0, /*hide_first_stop=*/true);
  EXPECT_TRUE(cal.stops()[0].skipped);
  EXPECT_LT(triangulation_rms(c), 0.002);
  RobotCalibration blind({});
  EXPECT_THROW(run_procedure(blind, 0.2, 1.0), CalibrationInputError);
  RobotCalibrationParams flat;
  flat.nz = 1;
  flat.nx = flat.ny = 4;
  EXPECT_THROW(RobotCalibration{flat}, CalibrationInputError);
}

// The default grid is inside the A465's reach tool-down: each wrist centre (0.226 m above the
// tool centre point) is 0.365 to 0.635 m from the shoulder at z = 0.33 m; the tool points down
// with yaw atan2(y, x) + pi (joint 6 near zero). (The full inverse kinematics of every stop is
// checked in tests/integration/robot_calibration_test.cpp.)
TEST(RobotCalibration, DefaultGridIsWithinReachToolDown) {
  RobotCalibration cal({});
  for (const auto& s : cal.stops()) {
    const Eigen::Vector3d wrist = s.tool + Eigen::Vector3d(0, 0, 0.226);
    const double reach = (wrist - Eigen::Vector3d(0, 0, 0.33)).norm();
    EXPECT_GT(reach, 0.375) << s.tool.transpose();
    EXPECT_LT(reach, 0.625) << s.tool.transpose();
    EXPECT_GE(s.tool.z(), 0.05);
    EXPECT_TRUE(s.rpy.isApprox(tool_down_rpy(s.tool)));
    EXPECT_NEAR(s.rpy.x(), M_PI, 1e-12);
    EXPECT_NEAR(std::remainder(s.rpy.z() - std::atan2(s.tool.y(), s.tool.x()) - M_PI, 2 * M_PI), 0,
                1e-12);
  }
  EXPECT_NEAR(tool_down_rpy({0.45, 0, 0.1}).z(), M_PI, 1e-12);
}

// A move the arm refuses skips its stop with the reason and goes on to the next.
TEST(RobotCalibration, RejectedMoveSkipsTheStop) {
  RobotCalibration cal({}, 10);
  const auto first = cal.next_target();
  ASSERT_TRUE(first);
  cal.on_arm_rejected(9, "older");  // not the pending command
  EXPECT_FALSE(cal.stops()[0].skipped);
  cal.on_arm_rejected(10, "out of reach");
  EXPECT_TRUE(cal.stops()[0].skipped);
  EXPECT_EQ(cal.stops()[0].rejected, "out of reach");
  const auto second = cal.next_target();
  ASSERT_TRUE(second);
  EXPECT_EQ(second->sequence, 11);
  EXPECT_TRUE(second->position.isApprox(cal.stops()[1].tool));
}

// The calibrate_robot section sets the box, grid, orientation and timing; bad values name the key.
TEST(RobotCalibration, ParamsFromConfig) {
  const auto p = load_robot_calibration_params(Config::parse(
      "calibrate_robot:\n  box_min: [0.40, -0.1, 0.1]\n  box_max: [0.5, 0.1, 0.2]\n"
      "  grid: [4, 3, 2]\n  tool_rpy: [3.14159, 0, 0]\n  frames_per_stop: 5\n  speed: 0.3\n"));
  EXPECT_DOUBLE_EQ(p.box_min.x(), 0.40);
  EXPECT_DOUBLE_EQ(p.box_max.z(), 0.2);
  EXPECT_EQ(p.nx * p.ny * p.nz, 24);
  ASSERT_TRUE(p.tool_rpy);
  EXPECT_EQ(p.frames_per_stop, 5);
  EXPECT_DOUBLE_EQ(p.speed, 0.3);
  EXPECT_EQ(RobotCalibration(p).stops().size(), 24u);
  EXPECT_FALSE(load_robot_calibration_params(Config()).tool_rpy);
  for (const char* bad :
       {"calibrate_robot:\n  grid: [3, 3, 1]\n", "calibrate_robot:\n  box_min: [0.6, 0, 0]\n",
        "calibrate_robot:\n  box_max: [1, 2]\n"}) {
    EXPECT_THROW(load_robot_calibration_params(Config::parse(bad)), ConfigError) << bad;
  }
}

// The ball held 12, -8 and 20 mm off the tool point, stops tilted by 0.3 rad: the hand-eye solve
// finds the offset within 0.5 mm on every axis and the cameras triangulate within 2 mm, where
// taking the ball at the tool point leaves them centimetres off.
TEST(RobotCalibration, HandEyeFindsTheBallsOffsetOnTheTool) {
  const Eigen::Vector3d offset(0.012, -0.008, 0.020);
  RobotCalibrationParams p;
  p.tilt = 0.3;
  RobotCalibration cal(p);
  const HandEyeSolution h = run_hand_eye(cal, 0.3, 0.0, false, offset);
  EXPECT_EQ(h.offset_dims, 3);
  EXPECT_TRUE(h.offset_accepted);
  EXPECT_LT(h.rms_estimated, 0.5 * h.rms_configured);
  EXPECT_LT((h.ball_offset - offset).cwiseAbs().maxCoeff(), 5e-4) << h.ball_offset.transpose();
  EXPECT_LT(triangulation_rms(h.cameras), 0.002);
  p.estimate_ball_offset = false;
  RobotCalibration fixed(p);
  const HandEyeSolution f = run_hand_eye(fixed, 0.3, 0.0, false, offset);
  EXPECT_EQ(f.ball_offset, Eigen::Vector3d::Zero());
  EXPECT_GT(triangulation_rms(f.cameras), 0.005);
  std::printf(
      "hand-eye: offset (%.2f, %.2f, %.2f) mm in %d rounds, 3D RMS %.3f mm (%.1f mm "
      "with the offset taken as zero)\n",
      h.ball_offset.x() * 1e3, h.ball_offset.y() * 1e3, h.ball_offset.z() * 1e3, h.iterations,
      triangulation_rms(h.cameras) * 1e3, triangulation_rms(f.cameras) * 1e3);
}

// With the ball where configured, an estimated offset explains no more than the pixels' noise
// and is not kept.
TEST(RobotCalibration, NoOffsetIsFoundWhereThereIsNone) {
  RobotCalibrationParams p;
  p.tilt = 0.3;
  RobotCalibration cal(p);
  const HandEyeSolution h = run_hand_eye(cal, 0.3, 0.0);
  EXPECT_EQ(h.offset_dims, 3);
  EXPECT_FALSE(h.offset_accepted);
  EXPECT_EQ(h.ball_offset, Eigen::Vector3d::Zero());
  EXPECT_LT(triangulation_rms(h.cameras), 0.002);
}

// Tool-down stops differ only in yaw: the offset across the tool is estimated, the one along its
// axis (which moves every stop alike) stays as configured.
TEST(RobotCalibration, ToolDownStopsObserveTheOffsetAcrossTheTool) {
  RobotCalibrationParams p;
  p.ball_offset = {0, 0, 0.005};
  RobotCalibration cal(p);
  const HandEyeSolution h = run_hand_eye(cal, 0.1, 0.0, false, {0.010, 0.004, 0.005});
  EXPECT_EQ(h.offset_dims, 2);
  EXPECT_NEAR(h.ball_offset.x(), 0.010, 1e-3);
  EXPECT_NEAR(h.ball_offset.y(), 0.004, 1e-3);
  EXPECT_NEAR(h.ball_offset.z(), 0.005, 1e-9);
  EXPECT_LT(triangulation_rms(h.cameras), 0.002);
}

// Only the lower half of the ball's outline shows at every stop (the palm hides the top): the
// centre fitted to it lies px off the centre's projection, and modelling that fit on the ball's
// exact image (sphere_outline_centre) brings the cameras back to where a whole ball puts them;
// each stop keeps every blob's sectors.
TEST(RobotCalibration, HalfOutlineIsModelledOnTheBallsImage) {
  constexpr uint64_t kLowerHalf = 0xFFFFFFFF00000000ULL;  // directions of +y: below the centre
  RobotCalibration whole({});
  const double whole_rms = triangulation_rms(run_procedure(whole, 0.3, 0.0));
  RobotCalibration modelled({});
  const HandEyeSolution h =
      run_hand_eye(modelled, 0.3, 0.0, false, Eigen::Vector3d::Zero(), 0.5, kLowerHalf);
  for (const auto& s : modelled.stops()) {
    ASSERT_EQ(s.blobs[1].size(), 10u);
    EXPECT_EQ(s.blobs[1][9].second, kLowerHalf);
  }
  RobotCalibrationParams p;
  p.ball_radius = 0;  // the image's radius only: the ellipse's centre, not the half's fit
  RobotCalibration unmodelled(p);
  const HandEyeSolution u =
      run_hand_eye(unmodelled, 0.3, 0.0, false, Eigen::Vector3d::Zero(), 0.5, kLowerHalf);
  EXPECT_LT(triangulation_rms(h.cameras), whole_rms + 0.0002);
  EXPECT_GT(triangulation_rms(u.cameras), 2 * triangulation_rms(h.cameras));
  std::printf("half outline: 3D RMS %.3f mm modelled, %.3f mm not, %.3f mm whole ball\n",
              triangulation_rms(h.cameras) * 1e3, triangulation_rms(u.cameras) * 1e3,
              whole_rms * 1e3);
}

// Any host can send BLOB_*: centres off the image, NaN or huge are refused and counted, radii that
// are no image's are not averaged, and stops of nothing else are skipped: no calibration is made
// from them.
TEST(RobotCalibration, BlobsNoCameraSentAreRefused) {
  RobotCalibration cal({});
  int64_t utime = 1'000'000;
  arrive_at_first_stop(cal, utime);
  const double inf = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& bad :
       {Eigen::Vector2d(NAN, 10), Eigen::Vector2d(10, inf), Eigen::Vector2d(-1e300, 10),
        Eigen::Vector2d(640, 10), Eigen::Vector2d(10, -0.6)}) {
    utime += 1'000'000;
    cal.on_blob(0, utime, true, bad, 0.9, 1e300, 0);
  }
  EXPECT_EQ(cal.stops()[0].refused, 5);
  EXPECT_EQ(cal.stops()[0].frames[0], 0);
  for (int k = 0; k < 10; ++k) {
    utime += 33'333;
    for (int c = 0; c < 2; ++c) cal.on_blob(c, utime, true, {320, 240}, NAN, 1e300);
  }
  EXPECT_EQ(cal.stops()[0].frames[0], 10);
  EXPECT_EQ(cal.stops()[0].radius[0], 0) << "no image has a ball 1e300 px across";
  RobotCalibration refusing({});
  for (int k = 0; !refusing.done() && k < 100000; ++k) {
    if (auto next = refusing.next_target()) refusing.on_arm_status(utime, next->sequence, true);
    utime += 33'333;
    refusing.on_blob(0, utime, true, {1e9, 1e9});
  }
  EXPECT_TRUE(refusing.done());
  for (const auto& s : refusing.stops()) EXPECT_TRUE(s.skipped);
  EXPECT_THROW(refusing.solve_hand_eye(), CalibrationInputError);
}

// Blobs whose fitted circle has too little outline (the gripper hides the ball) are not averaged:
// a stop where every blob is so is skipped, and the count says why.
TEST(RobotCalibration, MostlyHiddenBallIsLeftOut) {
  RobotCalibration cal({});
  int64_t utime = 1'000'000;
  arrive_at_first_stop(cal, utime);
  for (int k = 0; k < 200 && cal.stops()[0].frames[0] == 0 && !cal.stops()[0].skipped; ++k) {
    utime += 33'333;
    cal.on_blob(0, utime, true, {320, 240}, 0.3);
  }
  EXPECT_TRUE(cal.stops()[0].skipped);
  EXPECT_EQ(cal.stops()[0].frames[0], 0);
  EXPECT_EQ(cal.stops()[0].hidden, cal.stops()[0].misses);
  EXPECT_GT(cal.stops()[0].hidden, 0);
}

}  // namespace
}  // namespace sg::vision
