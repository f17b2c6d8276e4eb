// Kinematics of the CRS A465: forward kinematics against hand-derived poses, closed-form inverse
// kinematics round trips, the nearest solution within limits, orientation angles, move timing,
// and loading the geometry from configuration.

#include "arm_driver/kinematics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

namespace sg::arm {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

Joints joints(double q1, double q2, double q3, double q4, double q5, double q6) {
  Joints q;
  q << q1, q2, q3, q4, q5, q6;
  return q;
}

/// The rotation angle between two rotations (accurate near zero, unlike acos of the trace).
double rotation_error(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::Quaterniond(a).angularDistance(Eigen::Quaterniond(b));
}

/// The largest joint difference modulo 2 pi.
double wrapped_distance(const Joints& a, const Joints& b) {
  return (a - b)
      .unaryExpr([](double d) { return std::abs(std::remainder(d, 2 * kPi)); })
      .maxCoeff();
}

/// A tool pointing straight down (rpy = (pi, 0, 0)) with its centre at `xyz`.
Eigen::Isometry3d tool_down(double x, double y, double z) {
  return pose_from_xyz_rpy({x, y, z}, {kPi, 0, 0});
}

// The A465 defaults written out as the YAML section handed to config/stereograsp.yaml.
constexpr const char* kDefaultsYaml = R"(arm:
  dh:                      # modified DH rows: [alpha_deg, a_m, d_m, theta_offset_deg]
    - [0, 0, 0.330, 0]
    - [-90, 0, 0, -90]
    - [0, 0.305, 0, -90]
    - [-90, 0, 0.330, 0]
    - [90, 0, 0, 0]
    - [-90, 0, 0.076, 180]
  limits_deg: [[-175, 175], [-90, 90], [-110, 110], [-180, 180], [-105, 105], [-180, 180]]
  max_speed_deg_s: [180, 180, 180, 171, 173, 171]
  tool_offset: [0, 0, 0.15]        # TCP in the flange frame, m
  workspace_min: [-0.90, -0.90, 0.05]
  workspace_max: [0.90, 0.90, 1.25]
)";

/// Equal link by link (within 4 ulps, as EXPECT_DOUBLE_EQ), with the same tool and workspace.
::testing::AssertionResult same_geometry(const ArmGeometry& a, const ArmGeometry& b) {
  auto near = [](double x, double y) {
    return std::abs(x - y) <=
           4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(x));
  };
  for (int i = 0; i < 6; ++i) {
    const DhLink& p = a.links[i];
    const DhLink& q = b.links[i];
    if (!near(p.alpha, q.alpha) || !near(p.a, q.a) || !near(p.d, q.d) ||
        !near(p.theta_offset, q.theta_offset) || !near(p.min, q.min) || !near(p.max, q.max) ||
        !near(p.max_speed, q.max_speed)) {
      return ::testing::AssertionFailure() << "joint " << i + 1 << " differs";
    }
  }
  if (!a.tool.isApprox(b.tool, 1e-15)) return ::testing::AssertionFailure() << "tools differ";
  if (a.workspace.min != b.workspace.min || a.workspace.max != b.workspace.max) {
    return ::testing::AssertionFailure() << "workspaces differ";
  }
  return ::testing::AssertionSuccess();
}

/// The message of the ConfigError that loading `yaml` throws, or "" when it does not throw.
std::string load_error(const std::string& yaml) {
  try {
    load_arm_geometry(Config::parse(yaml, "arm.yaml"));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// q = 0 is the arm straight up: every frame's x, y, z parallel to the base's (the offsets of
// -90, -90 and 180 deg cancel the twists), so the TCP is at height
// d1 + a2 + d4 + d6 + tool = 0.330 + 0.305 + 0.330 + 0.076 + 0.150 = 1.191 m on the waist axis.
TEST(ForwardKinematics, ZeroPoseIsTheArmStraightUp) {
  const ArmGeometry arm = ArmGeometry::a465();
  const Eigen::Isometry3d tcp = forward_kinematics(arm, Joints::Zero());
  EXPECT_LT((tcp.translation() - Eigen::Vector3d(0, 0, 1.191)).norm(), 1e-12);
  EXPECT_LT(rotation_error(tcp.linear(), Eigen::Matrix3d::Identity()), 1e-12);
  EXPECT_LT((flange_pose(arm, Joints::Zero()).translation() - Eigen::Vector3d(0, 0, 1.041)).norm(),
            1e-12);
}

// q2 = +90 deg turns everything above the shoulder (z2 = +Y) by +90 deg about Y: the straight
// arm lies along +X, so the TCP is at (0.305 + 0.330 + 0.076 + 0.150, 0, 0.330) =
// (0.861, 0, 0.330) with the tool z axis along +X: R = Ry(90 deg).
TEST(ForwardKinematics, ShoulderAtNinetyDegreesStretchesForward) {
  const Eigen::Isometry3d tcp =
      forward_kinematics(ArmGeometry::a465(), joints(0, 90 * kDeg, 0, 0, 0, 0));
  EXPECT_LT((tcp.translation() - Eigen::Vector3d(0.861, 0, 0.330)).norm(), 1e-12);
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY()).matrix();
  EXPECT_LT(rotation_error(tcp.linear(), expected), 1e-12);
}

// q = (90, 0, 90, 0, 90, 0) deg: facing +Y, upper arm up to the elbow at z = 0.635, forearm
// horizontal to the wrist centre (0, 0.330, 0.635), wrist pitched another 90 deg so the tool
// points down: TCP (0, 0.330, 0.635 - 0.076 - 0.150) = (0, 0.330, 0.409). In the waist frame the
// tool turned 180 deg about the joint axes (Ry(180) = diag(-1, 1, -1)), then the waist turned
// 90 deg about Z: tool x = -Y, tool y = -X, tool z = -Z.
TEST(ForwardKinematics, ForearmLevelWristDown) {
  const Eigen::Isometry3d tcp =
      forward_kinematics(ArmGeometry::a465(), joints(90 * kDeg, 0, 90 * kDeg, 0, 90 * kDeg, 0));
  EXPECT_LT((tcp.translation() - Eigen::Vector3d(0, 0.330, 0.409)).norm(), 1e-12);
  Eigen::Matrix3d expected;
  expected << 0, -1, 0,  //
      -1, 0, 0,          //
      0, 0, -1;
  EXPECT_LT(rotation_error(tcp.linear(), expected), 1e-12);
}

// 10,000 random joint vectors within the limits: every IK solution reproduces the pose, one of
// them is the drawn vector, and solve_nearest from the drawn vector returns it.
TEST(InverseKinematics, RoundTripOfRandomJoints) {
  ArmGeometry arm = ArmGeometry::a465();
  arm.workspace = Workspace{};  // some random poses put the TCP under the table
  std::mt19937_64 rng(20240607);
  int checked = 0;
  while (checked < 10000) {
    Joints q;
    for (int i = 0; i < 6; ++i) {
      q[i] = std::uniform_real_distribution<double>(arm.links[i].min, arm.links[i].max)(rng);
    }
    if (std::abs(q[4]) < 1e-3) continue;  // the wrist singularity has its own test
    ++checked;
    const Eigen::Isometry3d target = forward_kinematics(arm, q);
    const std::vector<Joints> solutions = inverse_kinematics(arm, target);
    ASSERT_FALSE(solutions.empty()) << "q = " << q.transpose();
    double nearest = 1e9;
    for (const Joints& s : solutions) {
      const Eigen::Isometry3d pose = forward_kinematics(arm, s);
      ASSERT_LT((pose.translation() - target.translation()).norm(), 1e-9)
          << "q = " << q.transpose();
      ASSERT_LT(rotation_error(pose.linear(), target.linear()), 1e-9) << "q = " << q.transpose();
      ASSERT_LE(s.cwiseAbs().maxCoeff(), kPi);
      nearest = std::min(nearest, wrapped_distance(s, q));
    }
    ASSERT_LT(nearest, 1e-9) << "q = " << q.transpose();
    const IkResult ik = solve_nearest(arm, target, q);
    ASSERT_TRUE(ik.joints) << ik.error << " for q = " << q.transpose();
    ASSERT_LT((*ik.joints - q).cwiseAbs().maxCoeff(), 1e-9) << "q = " << q.transpose();
    ASSERT_TRUE(within_limits(arm, *ik.joints));
  }
}

// The closed form is not tied to the A465's numbers: with a shoulder offset a_1, a lateral
// offset d_2 + d_3, an elbow offset a_3, other theta offsets, opposite twist signs and a tool off
// the flange axis, every solution still reproduces the pose and one is the drawn vector.
TEST(InverseKinematics, RoundTripWithOffsetsAndOtherTwistSigns) {
  ArmGeometry arm = ArmGeometry::a465();
  arm.links[1].a = 0.05, arm.links[1].d = 0.03, arm.links[2].d = 0.07, arm.links[3].a = 0.02;
  arm.links[0].theta_offset = 1.0, arm.links[2].theta_offset = 0.3;
  arm.links[1].alpha = arm.links[3].alpha = arm.links[5].alpha = kPi / 2;
  arm.links[4].alpha = -kPi / 2;
  arm.tool = Eigen::Translation3d(0.01, 0.02, 0.10);
  ASSERT_EQ(ik_structure_problem(arm.links), "");
  std::mt19937_64 rng(99);
  for (int n = 0; n < 1000; ++n) {
    Joints q;
    for (int i = 0; i < 6; ++i) {
      q[i] = std::uniform_real_distribution<double>(arm.links[i].min, arm.links[i].max)(rng);
    }
    if (std::abs(q[4]) < 1e-3) continue;
    const Eigen::Isometry3d target = forward_kinematics(arm, q);
    double nearest = 1e9;
    for (const Joints& s : inverse_kinematics(arm, target)) {
      const Eigen::Isometry3d pose = forward_kinematics(arm, s);
      ASSERT_LT((pose.translation() - target.translation()).norm(), 1e-9)
          << "q = " << q.transpose();
      ASSERT_LT(rotation_error(pose.linear(), target.linear()), 1e-9) << "q = " << q.transpose();
      nearest = std::min(nearest, wrapped_distance(s, q));
    }
    ASSERT_LT(nearest, 1e-9) << "q = " << q.transpose();
  }
}

// Straight up, the wrist centre is on the waist axis and the wrist is straight: q1 + q4 + q6 is
// all the pose fixes, so solve_nearest keeps q1 and q4 where they are and turns only q6.
TEST(InverseKinematics, SingularPoseKeepsTheFreeJoints) {
  const ArmGeometry arm = ArmGeometry::a465();
  const Eigen::Isometry3d up = forward_kinematics(arm, Joints::Zero());
  bool has_zero = false;
  for (const Joints& s : inverse_kinematics(arm, up)) has_zero |= s.cwiseAbs().maxCoeff() < 1e-9;
  EXPECT_TRUE(has_zero);
  const IkResult ik = solve_nearest(arm, up, joints(0.3, 0, 0, 0.2, 0, 0));
  ASSERT_TRUE(ik.joints) << ik.error;
  EXPECT_LT((*ik.joints - joints(0.3, 0, 0, 0.2, 0, -0.5)).cwiseAbs().maxCoeff(), 1e-9);
}

// Of the up to 8 solutions, solve_nearest takes the one closest in time to the current joints:
// from the elbow-down, wrist-flipped twin of a pose it returns that twin.
TEST(InverseKinematics, NearestPicksTheSolutionClosestInTime) {
  const ArmGeometry arm = ArmGeometry::a465();
  const Joints elbow_up = joints(0.1, 0.3, 0.8, 0.2, 0.5, 0.4);
  const Eigen::Isometry3d target = forward_kinematics(arm, elbow_up);
  for (const Joints& s : inverse_kinematics(arm, target)) {
    if (!within_limits(arm, s)) continue;
    const IkResult ik = solve_nearest(arm, target, s);
    ASSERT_TRUE(ik.joints);
    EXPECT_LT((*ik.joints - s).cwiseAbs().maxCoeff(), 1e-9);
  }
}

// With a wrist roll allowed over +-270 deg, the 2 pi equivalent nearest the current angle wins:
// from q6 = 3.0 rad a target needing q6 = -3.0 rad is reached at 2 pi - 3.0 = 3.283 rad.
TEST(InverseKinematics, NearestConsidersTwoPiEquivalents) {
  ArmGeometry arm = ArmGeometry::a465();
  arm.links[5].min = -270 * kDeg;
  arm.links[5].max = 270 * kDeg;
  const Joints start = joints(0.1, 0.3, 0.8, 0.2, 0.5, 3.0);
  const Eigen::Isometry3d target = forward_kinematics(arm, joints(0.1, 0.3, 0.8, 0.2, 0.5, -3.0));
  const IkResult ik = solve_nearest(arm, target, start);
  ASSERT_TRUE(ik.joints) << ik.error;
  EXPECT_LT((*ik.joints - joints(0.1, 0.3, 0.8, 0.2, 0.5, 2 * kPi - 3.0)).cwiseAbs().maxCoeff(),
            1e-9);
}

// A wrist centre 1.16 m from the shoulder (the arm reaches 0.635 m) has no solution.
TEST(InverseKinematics, BeyondReachHasNoSolution) {
  const ArmGeometry arm = ArmGeometry::a465();
  const Eigen::Isometry3d far = tool_down(0.85, 0.0, 0.90);  // inside the workspace box
  EXPECT_TRUE(inverse_kinematics(arm, far).empty());
  const IkResult ik = solve_nearest(arm, far, Joints::Zero());
  EXPECT_FALSE(ik.joints);
  EXPECT_EQ(ik.error, "out of reach");
}

// Every solution for the pose of q = (0, 0.5, 2.0, 0, 0, 0) rad bends the elbow by |q3| = 2.0 rad
// (114.6 deg, the limit is 110 deg), so the pose is reachable only outside joint 3's limits.
TEST(InverseKinematics, PoseOutsideLimitsNamesTheJoint) {
  const ArmGeometry arm = ArmGeometry::a465();
  const Eigen::Isometry3d target = forward_kinematics(arm, joints(0, 0.5, 2.0, 0, 0, 0));
  ASSERT_TRUE(arm.workspace.contains(target.translation()));
  const std::vector<Joints> solutions = inverse_kinematics(arm, target);
  ASSERT_FALSE(solutions.empty());
  for (const Joints& s : solutions) {
    EXPECT_NEAR(std::abs(s[2]), 2.0, 1e-9);
    EXPECT_FALSE(within_limits(arm, s));
  }
  const IkResult ik = solve_nearest(arm, target, Joints::Zero());
  EXPECT_FALSE(ik.joints);
  EXPECT_EQ(ik.error, "outside joint limits (joint 3)");
}

// A TCP at z = 0 (the table) is reachable within the limits but below the workspace box.
TEST(InverseKinematics, TargetOutsideTheWorkspaceIsRefused) {
  ArmGeometry arm = ArmGeometry::a465();
  const Eigen::Isometry3d on_table = tool_down(0.50, 0.0, 0.0);
  const IkResult ik = solve_nearest(arm, on_table, Joints::Zero());
  EXPECT_FALSE(ik.joints);
  EXPECT_EQ(ik.error, "outside the workspace");
  arm.workspace = Workspace{};
  EXPECT_TRUE(solve_nearest(arm, on_table, Joints::Zero()).joints);
}

// NaN in the target or in the current joints is an error, not a solution.
TEST(InverseKinematics, NonFiniteInputsAreRefused) {
  const ArmGeometry arm = ArmGeometry::a465();
  Eigen::Isometry3d bad = tool_down(0.45, 0, 0.10);
  bad.translation().x() = std::nan("");
  EXPECT_EQ(solve_nearest(arm, bad, Joints::Zero()).error, "target pose is not finite");
  EXPECT_EQ(solve_nearest(arm, tool_down(0.45, 0, 0.10), Joints::Constant(std::nan(""))).error,
            "current joints are not finite");
}

// The joint limits are inclusive and apply to each joint.
TEST(InverseKinematics, WithinLimits) {
  const ArmGeometry arm = ArmGeometry::a465();
  EXPECT_TRUE(within_limits(arm, Joints::Zero()));
  EXPECT_TRUE(within_limits(arm, joints(175 * kDeg, -90 * kDeg, 110 * kDeg, kPi, 0, -kPi)));
  EXPECT_FALSE(within_limits(arm, joints(0, 0, 0, 0, 106 * kDeg, 0)));
  EXPECT_FALSE(within_limits(arm, joints(-176 * kDeg, 0, 0, 0, 0, 0)));
}

// The ball's workspace in the paper's scenario, gripper pointing down: (0.45, 0, 0.10) and
// (0.60, 0, 0.10) are within the limits with the 0.15 m tool; (0.30, 0.15, 0.20) is too close to
// the base for it (the elbow would bend 113.5 deg) and needs a tool of 0.198 to 0.357 m.
TEST(InverseKinematics, TopDownGraspsOfTheBallWorkspace) {
  ArmGeometry arm = ArmGeometry::a465();
  for (const Eigen::Isometry3d& target : {tool_down(0.45, 0.0, 0.10), tool_down(0.60, 0.0, 0.10)}) {
    const IkResult ik = solve_nearest(arm, target, Joints::Zero());
    ASSERT_TRUE(ik.joints) << ik.error;
    EXPECT_LT((forward_kinematics(arm, *ik.joints).translation() - target.translation()).norm(),
              1e-9);
  }
  const Eigen::Isometry3d near = tool_down(0.30, 0.15, 0.20);
  EXPECT_EQ(solve_nearest(arm, near, Joints::Zero()).error, "outside joint limits (joint 3)");
  arm.tool = Eigen::Translation3d(0, 0, 0.25);
  for (const Eigen::Isometry3d& target :
       {tool_down(0.45, 0.0, 0.10), tool_down(0.60, 0.0, 0.10), near}) {
    EXPECT_TRUE(solve_nearest(arm, target, Joints::Zero()).joints);
  }
}

// rpy -> rotation -> rpy returns the same angles away from gimbal lock.
TEST(Rpy, RoundTrip) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-kPi, kPi), pitch(-1.5, 1.5);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d rpy(angle(rng), pitch(rng), angle(rng));
    const Eigen::Isometry3d pose = pose_from_xyz_rpy(Eigen::Vector3d::Zero(), rpy);
    EXPECT_LT((rpy_from_rotation(pose.linear()) - rpy).cwiseAbs().maxCoeff(), 1e-12);
  }
}

// At pitch = +-90 deg only roll - yaw (or roll + yaw) is defined: yaw comes back 0 and the roll
// carries the rest: (0.3, 90, 0.2) -> (0.1, 90, 0); (0.3, -90, 0.2) -> (0.5, -90, 0).
TEST(Rpy, GimbalLockIsResolvedWithYawZero) {
  for (const auto& [in, out] :
       {std::pair{Eigen::Vector3d(0.3, kPi / 2, 0.2), Eigen::Vector3d(0.1, kPi / 2, 0.0)},
        std::pair{Eigen::Vector3d(0.3, -kPi / 2, 0.2), Eigen::Vector3d(0.5, -kPi / 2, 0.0)}}) {
    const Eigen::Matrix3d R = pose_from_xyz_rpy(Eigen::Vector3d::Zero(), in).linear();
    const Eigen::Vector3d rpy = rpy_from_rotation(R);
    EXPECT_LT((rpy - out).cwiseAbs().maxCoeff(), 1e-9) << rpy.transpose();
    EXPECT_LT(rotation_error(pose_from_xyz_rpy(Eigen::Vector3d::Zero(), rpy).linear(), R), 1e-9);
  }
}

// rpy = (pi, 0, 0) turns the tool z axis to -Z (pointing down) and keeps its x axis along +X.
TEST(Rpy, RollPiPointsTheToolDown) {
  const Eigen::Isometry3d pose = pose_from_xyz_rpy({0.45, 0, 0.10}, {kPi, 0, 0});
  EXPECT_LT((pose.linear().col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 1e-15);
  EXPECT_LT((pose.linear().col(0) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-15);
  EXPECT_EQ(pose.translation(), Eigen::Vector3d(0.45, 0, 0.10));
}

// At 50% speed the waist covers 90 deg at 90 deg/s: 1.0 s; adding 171 deg of forearm roll at
// 85.5 deg/s makes the forearm the slowest joint: 2.0 s.
TEST(MotionTime, SlowestJointAtHalfSpeed) {
  const ArmGeometry arm = ArmGeometry::a465();
  EXPECT_NEAR(motion_time(arm, Joints::Zero(), joints(90 * kDeg, 0, 0, 0, 0, 0), 0.5), 1.0, 1e-12);
  EXPECT_NEAR(
      motion_time(arm, joints(0, 0, 0, -171 * kDeg, 0, 0), joints(90 * kDeg, 0, 0, 0, 0, 0), 0.5),
      2.0, 1e-12);
  EXPECT_THROW(motion_time(arm, Joints::Zero(), Joints::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(motion_time(arm, Joints::Zero(), Joints::Zero(), 1.5), std::invalid_argument);
}

// No "arm" section gives the A465; so does the YAML section written out with its values.
TEST(LoadArmGeometry, DefaultsAreTheA465) {
  EXPECT_TRUE(same_geometry(load_arm_geometry(Config()), ArmGeometry::a465()));
  EXPECT_TRUE(same_geometry(load_arm_geometry(Config::parse(kDefaultsYaml)), ArmGeometry::a465()));
}

// The shipped config/stereograsp.yaml describes the A465 of ArmGeometry::a465().
TEST(LoadArmGeometry, ShippedConfigIsTheA465) {
  const Config shipped = Config::load(std::string(SG_SOURCE_DIR) + "/config/stereograsp.yaml");
  ASSERT_TRUE(shipped.has("arm.dh"));
  EXPECT_TRUE(same_geometry(load_arm_geometry(shipped), ArmGeometry::a465()));
}

// Values in the file replace the defaults, degrees converted to radians.
TEST(LoadArmGeometry, ReadsValuesInDegreesAndMetres) {
  const ArmGeometry arm = load_arm_geometry(Config::parse(
      "arm:\n  max_speed_deg_s: [90, 90, 90, 90, 90, 45]\n  tool_offset: [0, 0.01, 0.2]\n"));
  EXPECT_DOUBLE_EQ(arm.links[0].max_speed, kPi / 2);
  EXPECT_DOUBLE_EQ(arm.links[5].max_speed, kPi / 4);
  EXPECT_EQ(arm.tool.translation(), Eigen::Vector3d(0, 0.01, 0.2));
  EXPECT_DOUBLE_EQ(arm.links[2].a, 0.305);
}

// A list of the wrong length, min >= max, a zero speed, a NaN and an unsolvable DH table are
// errors naming the key.
TEST(LoadArmGeometry, BadValuesNameTheKey) {
  const std::string length = load_error("arm:\n  max_speed_deg_s: [180, 180, 180, 171, 173]\n");
  EXPECT_NE(length.find("key 'arm.max_speed_deg_s': must be a list of 6 numbers, got 5"),
            std::string::npos)
      << length;
  const std::string limits = load_error(
      "arm:\n  limits_deg: [[-175, 175], [90, -90], [-110, 110], [-180, 180], [-105, 105], "
      "[-180, 180]]\n");
  EXPECT_NE(limits.find("key 'arm.limits_deg': row 2: min must be below max"), std::string::npos)
      << limits;
  const std::string speed = load_error("arm:\n  max_speed_deg_s: [180, 0, 180, 171, 173, 171]\n");
  EXPECT_NE(speed.find("key 'arm.max_speed_deg_s'"), std::string::npos) << speed;
  const std::string nan = load_error("arm:\n  tool_offset: [0, .nan, 0.15]\n");
  EXPECT_NE(nan.find("key 'arm.tool_offset'"), std::string::npos) << nan;
  const std::string row = load_error(
      "arm:\n  dh: [[0, 0, 0.33, 0], [-90, 0, 0, -90], [0, 0.305, 0, -90], [-90, 0, 0.33], "
      "[90, 0, 0, 0], [-90, 0, 0.076, 180]]\n");
  EXPECT_NE(row.find("key 'arm.dh': row 4 must be"), std::string::npos) << row;
  const std::string wrist = load_error(
      "arm:\n  dh: [[0, 0, 0.33, 0], [-90, 0, 0, -90], [0, 0.305, 0, -90], [-90, 0, 0.33, 0], "
      "[90, 0.02, 0, 0], [-90, 0, 0.076, 180]]\n");
  EXPECT_NE(wrist.find("key 'arm.dh'"), std::string::npos) << wrist;
}

}  // namespace
}  // namespace sg::arm
