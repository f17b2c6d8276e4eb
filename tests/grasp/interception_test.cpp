// Interception (grasp/interception.hpp): interpolating the predicted path, the leaned
// approach pose that keeps the wrist in the A465's comfortable shell, and the arrival-time fixed
// point on synthetic circular trajectories with a known controller delay.

#include "grasp/interception.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "arm_driver/kinematics.hpp"

namespace sg::grasp {
namespace {

using arm::forward_kinematics;
using arm::IkResult;
using arm::motion_time;
using arm::pose_from_xyz_rpy;
using arm::solve_nearest;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr int64_t kNow = 1'700'000'000'000'000;  // us since the epoch
constexpr int64_t kPeriod = 250'000;
constexpr double kLead = 0.78;  // s: the controller's delay
constexpr double kSpeed = 0.5;  // fraction of the joint speed limits

/// The wrist centre (where joints 4-6 meet) of the arm at q, from forward kinematics.
Eigen::Vector3d wrist_centre(const ArmGeometry& arm, const Joints& q) {
  const Eigen::Isometry3d flange = flange_pose(arm, q);
  return flange.translation() - arm.links[5].d * flange.linear().col(2);
}

Eigen::Vector3d shoulder(const ArmGeometry& arm) { return {0, 0, arm.links[0].d}; }

/// The paper's scenario: a circle of radius 0.15 m around (0.45, 0, 0.10) at `rpm`, starting at
/// `phase` when t = kNow, shifted by `drift` + `drift_speed` * (t - kNow) along Y.
struct Ball {
  double rpm = 1.0;
  double phase = 0;
  double drift = 0;
  double drift_speed = 0;
  Eigen::Vector3d at(int64_t t) const {
    const double s = static_cast<double>(t - kNow) * 1e-6;
    const double angle = phase + 2 * kPi * rpm / 60.0 * s;
    return {0.45 + 0.15 * std::cos(angle), drift + drift_speed * s + 0.15 * std::sin(angle), 0.10};
  }
};

/// The predictor's output for `ball` made at kNow: 16 points every 0.25 s from the true motion.
PredictedPath sampled(const Ball& ball) {
  PredictedPath path;
  path.utime = kNow;
  path.start_utime = kNow + kPeriod;
  path.period_us = kPeriod;
  for (int i = 0; i < 16; ++i) path.points.push_back(ball.at(path.start_utime + i * kPeriod));
  return path;
}

/// The arm waiting 15 cm above the circle's centre, tool down.
Joints waiting_joints(const ArmGeometry& arm) {
  const IkResult ik =
      solve_nearest(arm, pose_from_xyz_rpy({0.45, 0, 0.25}, {kPi, 0, kPi}), Joints::Zero());
  EXPECT_TRUE(ik.joints) << ik.error;
  return ik.joints.value_or(Joints::Zero());
}

/// T = now + lead + max(motion time, after_start) for the joints the interception chose.
int64_t arrival_for(const ArmGeometry& arm, const Joints& current, const Interception& aim,
                    double after_start) {
  const double move = motion_time(arm, current, aim.joints, kSpeed);
  return kNow + std::llround((kLead + std::max(move, after_start)) * 1e6);
}

PredictedPath three_points() {
  PredictedPath path;
  path.utime = 1'000'000;
  path.start_utime = 1'250'000;
  path.period_us = kPeriod;
  path.points = {{0, 0, 0}, {1, 2, 3}, {3, 2, 1}};
  return path;
}

// Halfway between two points the position is their mean; at the points it is the point itself.
TEST(PredictedPathTest, InterpolatesLinearlyAndIsExactAtPoints) {
  const PredictedPath path = three_points();
  EXPECT_EQ(path.end_utime(), 1'750'000);
  ASSERT_TRUE(path.at(1'375'000));
  EXPECT_TRUE(path.at(1'375'000)->isApprox(Eigen::Vector3d(0.5, 1.0, 1.5), 1e-15));
  ASSERT_TRUE(path.at(1'687'500));  // three quarters from (1,2,3) to (3,2,1)
  EXPECT_TRUE(path.at(1'687'500)->isApprox(Eigen::Vector3d(2.5, 2.0, 1.5), 1e-15));
  for (int i = 0; i < 3; ++i) {
    const std::optional<Eigen::Vector3d> p = path.at(path.start_utime + i * kPeriod);
    ASSERT_TRUE(p) << i;
    EXPECT_EQ(*p, path.points[i]) << i;
  }
}

// From utime to start_utime the first segment is extended backwards (one point: that point).
TEST(PredictedPathTest, ExtendsTheFirstSegmentBackToUtime) {
  PredictedPath path = three_points();
  ASSERT_TRUE(path.at(1'000'000));
  EXPECT_TRUE(path.at(1'000'000)->isApprox(Eigen::Vector3d(-1, -2, -3), 1e-15));
  ASSERT_TRUE(path.at(1'125'000));
  EXPECT_TRUE(path.at(1'125'000)->isApprox(Eigen::Vector3d(-0.5, -1, -1.5), 1e-15));
  path.points.resize(1);
  EXPECT_EQ(path.end_utime(), 1'250'000);
  ASSERT_TRUE(path.at(1'100'000));
  EXPECT_EQ(*path.at(1'100'000), Eigen::Vector3d(0, 0, 0));
}

// Before utime, after the last point, and on an empty or lost path there is no position.
TEST(PredictedPathTest, NothingOutsideTheHorizonOrWhenLost) {
  PredictedPath path = three_points();
  EXPECT_FALSE(path.at(999'999));
  EXPECT_FALSE(path.at(1'750'001));
  EXPECT_TRUE(path.at(1'750'000));
  path.lost = true;
  EXPECT_FALSE(path.at(1'375'000));
  PredictedPath empty;
  empty.utime = 0;
  empty.start_utime = 250'000;
  EXPECT_EQ(empty.end_utime(), 250'000);
  EXPECT_FALSE(empty.at(250'000));
}

// The sigmas interpolate like the points, but stay at sigmas[0] before start_utime (an error does
// not shrink toward zero by extrapolation); no sigmas or a lost path give none.
TEST(PredictedPathTest, SigmaInterpolatesAndHoldsBeforeTheFirstPoint) {
  PredictedPath path = three_points();
  EXPECT_FALSE(path.sigma_at(1'375'000));  // none carried
  path.sigmas = {{0.001, 0.002, 0.003}, {0.003, 0.004, 0.005}, {0.007, 0.008, 0.009}};
  ASSERT_TRUE(path.sigma_at(1'375'000));
  EXPECT_TRUE(path.sigma_at(1'375'000)->isApprox(Eigen::Vector3d(0.002, 0.003, 0.004), 1e-14));
  ASSERT_TRUE(path.sigma_at(1'750'000));
  EXPECT_EQ(*path.sigma_at(1'750'000), path.sigmas[2]);
  ASSERT_TRUE(path.sigma_at(1'000'000));
  EXPECT_EQ(*path.sigma_at(1'000'000), path.sigmas[0]);
  EXPECT_FALSE(path.sigma_at(1'750'001));
  path.sigmas.pop_back();  // not one per point: none
  EXPECT_FALSE(path.sigma_at(1'375'000));
}

// hold() stays at the position from utime to utime + count periods.
TEST(PredictedPathTest, HoldIsConstant) {
  const Eigen::Vector3d p(0.4, -0.1, 0.1);
  const PredictedPath path = PredictedPath::hold(p, 5'000'000);
  EXPECT_EQ(path.utime, 5'000'000);
  EXPECT_EQ(path.start_utime, 5'250'000);
  EXPECT_EQ(path.points.size(), 16u);
  EXPECT_FALSE(path.lost);
  EXPECT_EQ(path.end_utime(), 5'000'000 + 16 * kPeriod);
  for (int64_t t = 5'000'000; t <= path.end_utime(); t += 123'457) {
    ASSERT_TRUE(path.at(t)) << t;
    EXPECT_EQ(*path.at(t), p) << t;
  }
  EXPECT_FALSE(path.at(path.end_utime() + 1));
}

// Over the scenario's region (0.30..0.66 m from the base axis, every azimuth, also beyond the
// waist's +-175 deg where the arm reaches over backwards, z = 0.10) the pose has an IK solution
// whose TCP is the target, whose tool axis is the tilt's, whose wrist is within [wrist_min,
// wrist_max] (on the boundary when leaned), and whose joint 6 stays within +-90 deg; straight down
// wherever that already keeps the wrist within range.
TEST(ApproachPoseTest, ScenarioRegionIsReachableWithTheSmallestTilt) {
  const ArmGeometry arm = ArmGeometry::a465();
  const InterceptionSettings settings;
  const double L = arm.links[5].d + arm.tool.translation().z();  // 0.076 + 0.15
  const Joints current = waiting_joints(arm);
  int leaned = 0, straight = 0;
  for (double r = 0.30; r <= 0.66 + 1e-9; r += 0.02) {
    for (double az_deg = -180; az_deg <= 180; az_deg += 5) {
      const double az = az_deg * kDeg;
      const Eigen::Vector3d target(r * std::cos(az), r * std::sin(az), 0.10);
      const ApproachPose pose = approach_pose(arm, target, settings);
      SCOPED_TRACE("r = " + std::to_string(r) + ", azimuth = " + std::to_string(az_deg));
      EXPECT_EQ(pose.position, target);
      const IkResult ik = solve_nearest(arm, pose_from_xyz_rpy(pose.position, pose.rpy), current);
      ASSERT_TRUE(ik.joints) << ik.error;
      const Eigen::Isometry3d tcp = forward_kinematics(arm, *ik.joints);
      EXPECT_LT((tcp.translation() - target).norm(), 1e-9);
      const Eigen::Vector3d u(std::sin(pose.tilt) * std::cos(az),
                              std::sin(pose.tilt) * std::sin(az), -std::cos(pose.tilt));
      EXPECT_LT((tcp.linear().col(2) - u).norm(), 1e-9);
      const Eigen::Vector3d wrist = wrist_centre(arm, *ik.joints);
      EXPECT_LT((wrist - (target - L * u)).norm(), 1e-9);
      const double reach = (wrist - shoulder(arm)).norm();
      const double down = std::hypot(r, 0.10 - arm.links[0].d + L);  // wrist distance at tilt 0
      if (down >= settings.wrist_min && down <= settings.wrist_max) {
        EXPECT_EQ(pose.tilt, 0.0);
        ++straight;
      } else {
        ++leaned;
        EXPECT_LT(std::abs(pose.tilt), settings.max_tilt);
        EXPECT_NEAR(reach, down < settings.wrist_min ? settings.wrist_min : settings.wrist_max,
                    1e-9);
        // Too close: the tool leans inward (negative) and the wrist moves out, and vice versa.
        EXPECT_EQ(pose.tilt < 0, down < settings.wrist_min);
      }
      EXPECT_GE(reach, settings.wrist_min - 1e-9);
      EXPECT_LE(reach, settings.wrist_max + 1e-9);
      EXPECT_LE(std::abs((*ik.joints)[5]), 90 * kDeg);
    }
  }
  EXPECT_GT(leaned, 0);
  EXPECT_GT(straight, 0);
}

// Hand-built leans: the wrist put at (0.60, 0, 0.33) (0.60 m in front of the shoulder) with the
// tool leaned 30 deg outward gives the TCP (0.60 + L/2, 0, 0.33 - L cos 30); at (0.40, 0, 0.33)
// leaned 30 deg inward, (0.40 - L/2, 0, 0.33 - L cos 30). Both are the smallest leans that reach
// wrist_max and wrist_min (the distance is monotonic in the tilt between 0 and 30 deg there).
TEST(ApproachPoseTest, ReproducesHandBuiltLeans) {
  const ArmGeometry arm = ArmGeometry::a465();
  const InterceptionSettings settings;
  const double L = 0.226;
  const double c30 = std::sqrt(3.0) / 2;
  const ApproachPose out = approach_pose(arm, {0.60 + L / 2, 0, 0.33 - L * c30}, settings);
  EXPECT_NEAR(out.tilt, 30 * kDeg, 1e-12);
  const ApproachPose in = approach_pose(arm, {0.40 - L / 2, 0, 0.33 - L * c30}, settings);
  EXPECT_NEAR(in.tilt, -30 * kDeg, 1e-12);
  // Rotated to azimuth 90 deg the lean is the same and the yaw follows the azimuth.
  const ApproachPose side = approach_pose(arm, {0, 0.60 + L / 2, 0.33 - L * c30}, settings);
  EXPECT_NEAR(side.tilt, 30 * kDeg, 1e-12);
  const Eigen::Matrix3d R = pose_from_xyz_rpy(side.position, side.rpy).linear();
  EXPECT_LT((R.col(2) - Eigen::Vector3d(0, 0.5, -c30)).norm(), 1e-12);
}

// Straight down, the rotation is rpy (pi, 0, azimuth + pi): tool z down, tool x toward the base.
TEST(ApproachPoseTest, StraightDownIsSquareToTheBase) {
  const ArmGeometry arm = ArmGeometry::a465();
  const ApproachPose pose = approach_pose(arm, {0.0, 0.5, 0.10}, {});
  EXPECT_EQ(pose.tilt, 0.0);
  const Eigen::Matrix3d R = pose_from_xyz_rpy(pose.position, pose.rpy).linear();
  const Eigen::Matrix3d expected =
      pose_from_xyz_rpy(pose.position, {kPi, 0, kPi / 2 + kPi}).linear();
  EXPECT_LT((R - expected).norm(), 1e-12);
  EXPECT_LT((R.col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
  EXPECT_LT((R.col(0) - Eigen::Vector3d(0, -1, 0)).norm(), 1e-12);
}

// A target on the base axis has no azimuth: 0 is used, the tilt is clamped to max_tilt.
TEST(ApproachPoseTest, TargetOnTheBaseAxisUsesAzimuthZero) {
  const ArmGeometry arm = ArmGeometry::a465();
  const InterceptionSettings settings;
  const ApproachPose pose = approach_pose(arm, {0, 0, 0.10}, settings);
  EXPECT_TRUE(pose.rpy.allFinite());
  // The wrist is 0.004 m from the shoulder straight down; reaching 0.40 m needs more than 60 deg.
  EXPECT_DOUBLE_EQ(std::abs(pose.tilt), settings.max_tilt);
  const Eigen::Matrix3d R = pose_from_xyz_rpy(pose.position, pose.rpy).linear();
  const Eigen::Vector3d u(std::sin(pose.tilt), 0, -std::cos(pose.tilt));  // in the XZ plane
  EXPECT_LT((R.col(2) - u).norm(), 1e-12);
}

// On the circle at 1 and 2 rpm with a 0.78 s delay: T satisfies the fixed point to 1 ms, the aim
// is the true ball at T within 10 mm, and the simulated arm (arriving at now + lead + its move
// time) meets the true ball within 10 mm; a few iterations suffice.
TEST(InterceptTest, LandsOnACircularTrajectoryWithAKnownDelay) {
  const ArmGeometry arm = ArmGeometry::a465();
  const Joints current = waiting_joints(arm);
  for (const double rpm : {1.0, 2.0}) {
    for (double phase_deg = 0; phase_deg < 360; phase_deg += 30) {
      SCOPED_TRACE("rpm " + std::to_string(rpm) + ", phase " + std::to_string(phase_deg));
      const Ball ball{rpm, phase_deg * kDeg};
      const Interception aim =
          intercept(arm, sampled(ball), current, kNow, kLead, 0.0, {0, 0, 0}, kSpeed, {});
      ASSERT_TRUE(aim.ok) << aim.error;
      EXPECT_TRUE(aim.error.empty());
      EXPECT_LE(aim.iterations, 5);
      const int64_t arrival = arrival_for(arm, current, aim, 0.0);
      EXPECT_LE(std::abs(arrival - aim.arrival_utime), 1000);
      EXPECT_GT(aim.arrival_utime, kNow + 780'000);  // the arm has to move
      EXPECT_LT((aim.ball - ball.at(aim.arrival_utime)).norm(), 0.010);
      EXPECT_EQ(aim.pose.position, aim.ball);
      EXPECT_LT((ball.at(arrival) - aim.pose.position).norm(), 0.010);
      const Eigen::Isometry3d tcp = forward_kinematics(arm, aim.joints);
      EXPECT_LT((tcp.translation() - aim.pose.position).norm(), 1e-9);
    }
  }
}

// With an offset the tool aims above the ball; after_start longer than the move sets T.
TEST(InterceptTest, OffsetAndAfterStart) {
  const ArmGeometry arm = ArmGeometry::a465();
  const Joints current = waiting_joints(arm);
  const Ball ball{2.0, 1.0};
  const Interception above =
      intercept(arm, sampled(ball), current, kNow, kLead, 0.0, {0, 0, 0.10}, kSpeed, {});
  ASSERT_TRUE(above.ok) << above.error;
  EXPECT_TRUE(above.pose.position.isApprox(above.ball + Eigen::Vector3d(0, 0, 0.10), 1e-15));
  EXPECT_LE(std::abs(arrival_for(arm, current, above, 0.0) - above.arrival_utime), 1000);

  // A 3 s after_start is longer than any move here: T = now + 0.78 + 3 s exactly.
  const Interception late =
      intercept(arm, sampled(ball), current, kNow, kLead, 3.0, {0, 0, 0.10}, kSpeed, {});
  ASSERT_TRUE(late.ok) << late.error;
  EXPECT_LT(motion_time(arm, current, late.joints, kSpeed), 3.0);
  EXPECT_EQ(late.arrival_utime, kNow + 3'780'000);
  EXPECT_LT((late.ball - ball.at(late.arrival_utime)).norm(), 0.001);
}

// The scenario (circle plus a drift of up to +-0.2 m along Y at 0.01 m/s, from the waiting pose
// or the candle) converges within 5 iterations.
TEST(InterceptTest, ConvergesInFewIterations) {
  const ArmGeometry arm = ArmGeometry::a465();
  for (const Joints& current : {waiting_joints(arm), Joints::Zero().eval()}) {
    for (double drift = -0.2; drift <= 0.2 + 1e-9; drift += 0.1) {
      for (double phase_deg = 0; phase_deg < 360; phase_deg += 45) {
        SCOPED_TRACE("drift " + std::to_string(drift) + ", phase " + std::to_string(phase_deg));
        const Ball ball{1.0, phase_deg * kDeg, drift, drift > 0 ? -0.01 : 0.01};
        const Interception aim =
            intercept(arm, sampled(ball), current, kNow, kLead, 0.0, {0, 0, 0}, kSpeed, {});
        ASSERT_TRUE(aim.ok) << aim.error;
        EXPECT_GE(aim.iterations, 1);
        EXPECT_LE(aim.iterations, 5);
        EXPECT_LE(std::abs(arrival_for(arm, current, aim, 0.0) - aim.arrival_utime), 1000);
        EXPECT_LT((aim.ball - ball.at(aim.arrival_utime)).norm(), 0.010);
      }
    }
  }
}

// A lost track refuses with an error.
TEST(InterceptTest, RefusesALostPath) {
  const ArmGeometry arm = ArmGeometry::a465();
  PredictedPath path = PredictedPath::hold({0.45, 0, 0.10}, kNow);
  path.lost = true;
  const Interception aim =
      intercept(arm, path, waiting_joints(arm), kNow, kLead, 0.0, {0, 0, 0}, kSpeed, {});
  EXPECT_FALSE(aim.ok);
  EXPECT_NE(aim.error.find("lost"), std::string::npos) << aim.error;
  PredictedPath empty;
  empty.utime = kNow;
  const Interception none =
      intercept(arm, empty, waiting_joints(arm), kNow, kLead, 0.0, {0, 0, 0}, kSpeed, {});
  EXPECT_FALSE(none.ok);
  EXPECT_FALSE(none.error.empty());
}

// An arrival after the path's last point (a 10 s lead on a 4 s path) refuses.
TEST(InterceptTest, RefusesBeyondTheHorizon) {
  const ArmGeometry arm = ArmGeometry::a465();
  const PredictedPath path = PredictedPath::hold({0.45, 0, 0.10}, kNow);
  const Interception aim =
      intercept(arm, path, waiting_joints(arm), kNow, 10.0, 0.0, {0, 0, 0}, kSpeed, {});
  EXPECT_FALSE(aim.ok);
  EXPECT_NE(aim.error.find("horizon"), std::string::npos) << aim.error;
  EXPECT_EQ(aim.arrival_utime, kNow + 10'000'000);
}

// A TCP target lower than table_z + table_margin refuses (0.10 - 0.08 = 0.02 < 0.05).
TEST(InterceptTest, RefusesBelowTheTable) {
  const ArmGeometry arm = ArmGeometry::a465();
  const PredictedPath path = PredictedPath::hold({0.45, 0, 0.10}, kNow);
  const Interception aim =
      intercept(arm, path, waiting_joints(arm), kNow, kLead, 0.0, {0, 0, -0.08}, kSpeed, {});
  EXPECT_FALSE(aim.ok);
  EXPECT_NE(aim.error.find("table"), std::string::npos) << aim.error;
  InterceptionSettings raised;
  raised.table_z = 0.06;  // 0.10 < 0.06 + 0.05
  const Interception high =
      intercept(arm, path, waiting_joints(arm), kNow, kLead, 0.0, {0, 0, 0}, kSpeed, raised);
  EXPECT_FALSE(high.ok);
  EXPECT_NE(high.error.find("table"), std::string::npos) << high.error;
}

// A target outside geometry.workspace refuses.
TEST(InterceptTest, RefusesOutsideTheWorkspace) {
  ArmGeometry arm = ArmGeometry::a465();
  const Joints current = waiting_joints(arm);
  arm.workspace.max.x() = 0.40;
  const PredictedPath path = PredictedPath::hold({0.45, 0, 0.10}, kNow);
  const Interception aim = intercept(arm, path, current, kNow, kLead, 0.0, {0, 0, 0}, kSpeed, {});
  EXPECT_FALSE(aim.ok);
  EXPECT_NE(aim.error.find("workspace"), std::string::npos) << aim.error;
}

// A target inside the workspace box but 1.2 m from the base axis (reach 0.861 m) refuses.
TEST(InterceptTest, RefusesAnUnreachableTarget) {
  const ArmGeometry arm = ArmGeometry::a465();
  const PredictedPath path = PredictedPath::hold({0.85, 0.85, 0.10}, kNow);
  const Interception aim =
      intercept(arm, path, waiting_joints(arm), kNow, kLead, 0.0, {0, 0, 0}, kSpeed, {});
  EXPECT_FALSE(aim.ok);
  EXPECT_NE(aim.error.find("unreachable"), std::string::npos) << aim.error;
}

// One iteration cannot converge when the arm has to move (T moves by the move time), and an
// invalid speed refuses instead of throwing.
TEST(InterceptTest, RefusesWithoutConvergenceOrWithABadSpeed) {
  const ArmGeometry arm = ArmGeometry::a465();
  const Joints current = waiting_joints(arm);
  InterceptionSettings once;
  once.max_iterations = 1;
  const Interception aim =
      intercept(arm, sampled(Ball{1.0, 0.0}), current, kNow, kLead, 0.0, {0, 0, 0}, kSpeed, once);
  EXPECT_FALSE(aim.ok);
  EXPECT_NE(aim.error.find("did not converge"), std::string::npos) << aim.error;
  EXPECT_EQ(aim.iterations, 1);
  const Interception bad =
      intercept(arm, sampled(Ball{1.0, 0.0}), current, kNow, kLead, 0.0, {0, 0, 0}, 0.0, {});
  EXPECT_FALSE(bad.ok);
  EXPECT_FALSE(bad.error.empty());
}

}  // namespace
}  // namespace sg::grasp
