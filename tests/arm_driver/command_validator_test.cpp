// The command validator: an accepted Cartesian target becomes joints that reproduce the pose, and
// every bad command (not finite, outside the workspace, out of reach, beyond the joint limits, a
// bad speed, an old sequence number, an unknown mode) is rejected with a reason naming the fault.

#include "arm_driver/command_validator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "tests/support/arm_commands.hpp"

namespace sg::arm {
namespace {

using Cmd = stereograsp::arm_cmd_t;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Where the emulated arm powers up (C550Params::ready): elbow and wrist at 90 degrees.
Joints ready_joints() {
  Joints q;
  q << 0, 0, kPi / 2, 0, kPi / 2, 0;
  return q;
}

/// A tool-down Cartesian command with yaw pi/2, which keeps joint 6 at +90 degrees for targets on
/// the X axis, away from its +-180 degree limit.
Cmd cartesian(int64_t sequence, double x, double y, double z) {
  return test::tool_down_move(sequence, x, y, z, kPi / 2);
}

/// A joint command to `q` (radians).
Cmd joint_command(int64_t sequence, const Joints& q) {
  Cmd c{};
  c.sequence = sequence;
  c.mode = Cmd::MODE_JOINTS;
  for (int i = 0; i < 6; ++i) c.joints[i] = q[i];
  c.gripper = Cmd::GRIPPER_KEEP;
  c.speed = 0.5;
  c.sender = "test";
  return c;
}

/// Passes when `result` is a rejection whose reason contains `expected`.
testing::AssertionResult rejected_with(const ValidationResult& result,
                                       const std::string& expected) {
  if (result.target) {
    return testing::AssertionFailure()
           << "accepted, expected a rejection with '" << expected << "'";
  }
  if (result.reason.find(expected) == std::string::npos) {
    return testing::AssertionFailure()
           << "reason '" << result.reason << "' does not contain '" << expected << "'";
  }
  return testing::AssertionSuccess();
}

// A reachable tool-down target inside the workspace is accepted as joints within the limits whose
// forward kinematics reproduce the commanded position and orientation.
TEST(CommandValidatorTest, AcceptsReachableCartesianTargetWithJointsThatReproduceThePose) {
  const ArmGeometry arm = ArmGeometry::a465();
  CommandValidator validator(arm);
  Cmd command = cartesian(7, 0.45, 0.0, 0.20);
  command.gripper = Cmd::GRIPPER_CLOSE;
  command.speed = 0.25;
  command.source_utime = 123456;

  const ValidationResult result = validator.validate(command, ready_joints());

  ASSERT_TRUE(result.target) << result.reason;
  EXPECT_EQ(result.reason, "");
  const ArmTarget& target = *result.target;
  EXPECT_EQ(target.sequence, 7);
  EXPECT_EQ(target.mode, Cmd::MODE_CARTESIAN);
  EXPECT_TRUE(target.moves_arm());
  EXPECT_EQ(target.gripper, Cmd::GRIPPER_CLOSE);
  EXPECT_DOUBLE_EQ(target.speed, 0.25);
  EXPECT_EQ(target.source_utime, 123456);
  EXPECT_EQ(target.sender, "test");
  EXPECT_TRUE(within_limits(arm, target.joints));
  EXPECT_NEAR(target.joints[5], 90 * kDeg, 1e-9);  // yaw pi/2 keeps joint 6 off its limit
  const Eigen::Isometry3d reached = forward_kinematics(arm, target.joints);
  const Eigen::Isometry3d wanted = pose_from_xyz_rpy({0.45, 0.0, 0.20}, {kPi, 0, kPi / 2});
  EXPECT_LT((reached.translation() - wanted.translation()).norm(), 1e-9);
  EXPECT_LT((reached.linear() - wanted.linear()).norm(), 1e-9);
}

// Of the arm's configurations the validator picks the one nearest the reference joints: from the
// ready pose, the waist faces the target and the elbow stays up (q3 > 0).
TEST(CommandValidatorTest, ChoosesTheSolutionNearestTheReference) {
  const ArmGeometry arm = ArmGeometry::a465();
  CommandValidator validator(arm);

  const ValidationResult result =
      validator.validate(cartesian(1, 0.40, 0.10, 0.25), ready_joints());

  ASSERT_TRUE(result.target) << result.reason;
  EXPECT_NEAR(result.target->joints[0], std::atan2(0.10, 0.40), 1e-9);
  EXPECT_GT(result.target->joints[2], 0);
  const Eigen::Vector3d reached = forward_kinematics(arm, result.target->joints).translation();
  EXPECT_LT((reached - Eigen::Vector3d(0.40, 0.10, 0.25)).norm(), 1e-9);
}

// A joint command within the limits is accepted unchanged.
TEST(CommandValidatorTest, AcceptsJointCommandWithinLimits) {
  CommandValidator validator(ArmGeometry::a465());
  Joints q;
  q << 10 * kDeg, 20 * kDeg, 80 * kDeg, -30 * kDeg, 60 * kDeg, 45 * kDeg;

  const ValidationResult result = validator.validate(joint_command(1, q), ready_joints());

  ASSERT_TRUE(result.target) << result.reason;
  EXPECT_EQ(result.target->mode, Cmd::MODE_JOINTS);
  EXPECT_EQ(result.target->joints, q);
}

// NaN or an infinity in any position or orientation field of a Cartesian command is rejected as
// not finite.
TEST(CommandValidatorTest, RejectsNonFiniteCartesianFields) {
  CommandValidator validator(ArmGeometry::a465());
  int64_t sequence = 0;
  for (const double bad : {kNan, kInf, -kInf}) {
    for (int i = 0; i < 6; ++i) {
      Cmd command = cartesian(++sequence, 0.45, 0.0, 0.20);
      (i < 3 ? command.position[i] : command.orientation[i - 3]) = bad;
      EXPECT_TRUE(rejected_with(validator.validate(command, ready_joints()),
                                "position or orientation is not finite"))
          << "field " << i << " = " << bad;
    }
  }
}

// NaN or an infinity in any joint of a joint command is rejected as not finite.
TEST(CommandValidatorTest, RejectsNonFiniteJoints) {
  CommandValidator validator(ArmGeometry::a465());
  int64_t sequence = 0;
  for (const double bad : {kNan, kInf, -kInf}) {
    for (int i = 0; i < 6; ++i) {
      Cmd command = joint_command(++sequence, ready_joints());
      command.joints[i] = bad;
      EXPECT_TRUE(
          rejected_with(validator.validate(command, ready_joints()), "a joint angle is not finite"))
          << "joint " << i + 1 << " = " << bad;
    }
  }
}

// NaN or an infinite speed is rejected, in every mode.
TEST(CommandValidatorTest, RejectsNonFiniteSpeed) {
  CommandValidator validator(ArmGeometry::a465());
  int64_t sequence = 0;
  for (const double bad : {kNan, kInf, -kInf}) {
    Cmd move = cartesian(++sequence, 0.45, 0.0, 0.20);
    move.speed = bad;
    EXPECT_TRUE(rejected_with(validator.validate(move, ready_joints()), "is outside (0, 1]"))
        << "speed " << bad;
    Cmd home{};
    home.sequence = ++sequence;
    home.mode = Cmd::MODE_HOME;
    home.speed = bad;
    home.sender = "test";
    EXPECT_TRUE(rejected_with(validator.validate(home, ready_joints()), "is outside (0, 1]"))
        << "speed " << bad;
  }
}

// A reachable-looking target outside the workspace box (below the table guard, beyond x and y)
// is rejected as outside the workspace.
TEST(CommandValidatorTest, RejectsTargetOutsideWorkspaceBox) {
  CommandValidator validator(ArmGeometry::a465());
  EXPECT_TRUE(rejected_with(validator.validate(cartesian(1, 0.45, 0.0, 0.04), ready_joints()),
                            "target (0.450, 0.000, 0.040) m is outside the workspace"));
  EXPECT_TRUE(rejected_with(validator.validate(cartesian(2, 0.95, 0.0, 0.30), ready_joints()),
                            "target (0.950, 0.000, 0.300) m is outside the workspace"));
  EXPECT_TRUE(rejected_with(validator.validate(cartesian(3, 0.0, -0.91, 0.30), ready_joints()),
                            "target (0.000, -0.910, 0.300) m is outside the workspace"));
  EXPECT_TRUE(rejected_with(validator.validate(cartesian(4, 0.3, 0.0, 1.30), ready_joints()),
                            "target (0.300, 0.000, 1.300) m is outside the workspace"));
}

// A point inside the box but too far from the shoulder for a tool-down pose (wrist centre 0.872 m
// from the shoulder, the arm reaches 0.635 m) is rejected as out of reach.
TEST(CommandValidatorTest, RejectsUnreachablePointInsideWorkspace) {
  CommandValidator validator(ArmGeometry::a465());
  ASSERT_TRUE(ArmGeometry::a465().workspace.contains({0.85, 0.0, 0.30}));

  const ValidationResult result = validator.validate(cartesian(1, 0.85, 0.0, 0.30), ready_joints());

  EXPECT_TRUE(rejected_with(result, "target (0.850, 0.000, 0.300) m: out of reach"));
}

// A Cartesian target whose only solutions fold the elbow past its +-110 degree limit is rejected
// naming joint 3.
TEST(CommandValidatorTest, RejectsCartesianTargetBeyondJointLimits) {
  CommandValidator validator(ArmGeometry::a465());

  const ValidationResult result = validator.validate(cartesian(1, 0.05, 0.0, 0.10), ready_joints());

  EXPECT_TRUE(rejected_with(result, "outside joint limits (joint 3)"));
}

// A joint command with any joint just beyond its limit is rejected; exactly at the limit it is
// accepted.
TEST(CommandValidatorTest, RejectsJointsBeyondLimits) {
  const ArmGeometry arm = ArmGeometry::a465();
  CommandValidator validator(arm);
  int64_t sequence = 0;
  for (int i = 0; i < 6; ++i) {
    for (const bool high : {false, true}) {
      Joints q = ready_joints();
      q[i] = high ? arm.links[i].max + 1e-6 : arm.links[i].min - 1e-6;
      EXPECT_TRUE(rejected_with(validator.validate(joint_command(++sequence, q), ready_joints()),
                                "joints outside their limits"))
          << "joint " << i + 1 << (high ? " above" : " below");
    }
  }
  Joints at_limit = ready_joints();
  at_limit[5] = arm.links[5].max;  // joint 6 at +180 degrees
  EXPECT_TRUE(validator.validate(joint_command(++sequence, at_limit), ready_joints()).target);
}

// A joint command within the limits that puts the tool below the table guard (z < 0.05 m) is
// rejected as outside the workspace.
TEST(CommandValidatorTest, RejectsJointsThatPutTheToolOutsideWorkspace) {
  const ArmGeometry arm = ArmGeometry::a465();
  CommandValidator validator(arm);
  Joints q;
  q << 0, 90 * kDeg, 90 * kDeg, 0, 0, 0;  // upper arm horizontal, forearm and tool hanging down
  const double z = forward_kinematics(arm, q).translation().z();
  ASSERT_NEAR(z, 0.330 - 0.330 - 0.076 - 0.15, 1e-9);
  ASSERT_TRUE(within_limits(arm, q));

  EXPECT_TRUE(rejected_with(validator.validate(joint_command(1, q), ready_joints()),
                            "outside the workspace"));
}

// Speeds of 0, below 0 and above 1 are rejected; 1 itself and a small positive speed pass.
TEST(CommandValidatorTest, RejectsSpeedOutsideZeroToOne) {
  CommandValidator validator(ArmGeometry::a465());
  int64_t sequence = 0;
  for (const double bad : {0.0, -0.0, -0.5, 1.0000001, 2.0}) {
    Cmd command = cartesian(++sequence, 0.45, 0.0, 0.20);
    command.speed = bad;
    EXPECT_TRUE(rejected_with(validator.validate(command, ready_joints()), "is outside (0, 1]"))
        << "speed " << bad;
  }
  for (const double good : {1.0, 0.01}) {
    Cmd command = cartesian(++sequence, 0.45, 0.0, 0.20);
    command.speed = good;
    EXPECT_TRUE(validator.validate(command, ready_joints()).target) << "speed " << good;
  }
}

// A sequence number older than the sender's last is rejected naming both numbers; one equal to
// it is a duplicate (no target, not a rejection); another sender counts on its own; a newer
// number from the first sender is accepted again.
TEST(CommandValidatorTest, RejectsSequenceNotNewerPerSender) {
  CommandValidator validator(ArmGeometry::a465());
  ASSERT_TRUE(validator.validate(cartesian(10, 0.45, 0.0, 0.20), ready_joints()).target);

  const ValidationResult again = validator.validate(cartesian(10, 0.45, 0.0, 0.20), ready_joints());
  EXPECT_FALSE(again.target);
  EXPECT_TRUE(again.duplicate);
  EXPECT_EQ(again.reason, "duplicate of command 10 from 'test'");
  EXPECT_TRUE(rejected_with(validator.validate(cartesian(9, 0.45, 0.0, 0.20), ready_joints()),
                            "sequence 9 from 'test' is not newer than 10"));
  EXPECT_EQ(validator.last_sequence("test"), 10);
  EXPECT_EQ(validator.last_sequence("nobody"), -1);

  Cmd other = cartesian(1, 0.45, 0.0, 0.20);
  other.sender = "sg-arm-ctl";
  EXPECT_TRUE(validator.validate(other, ready_joints()).target);
  other.sequence = 0;
  EXPECT_TRUE(rejected_with(validator.validate(other, ready_joints()),
                            "sequence 0 from 'sg-arm-ctl' is not newer than 1"));

  EXPECT_TRUE(validator.validate(cartesian(11, 0.45, 0.0, 0.20), ready_joints()).target);
}

// A rejected command still advances its sender's sequence: resending its number is a duplicate
// (not validated again), an older one is rejected.
TEST(CommandValidatorTest, RejectedCommandAdvancesTheSequence) {
  CommandValidator validator(ArmGeometry::a465());
  Cmd bad = cartesian(5, 0.85, 0.0, 0.30);  // out of reach
  ASSERT_FALSE(validator.validate(bad, ready_joints()).target);

  EXPECT_TRUE(validator.validate(cartesian(5, 0.45, 0.0, 0.20), ready_joints()).duplicate);
  EXPECT_TRUE(rejected_with(validator.validate(cartesian(4, 0.45, 0.0, 0.20), ready_joints()),
                            "sequence 4 from 'test' is not newer than 5"));
}

// Modes outside MODE_CARTESIAN..MODE_STOP are rejected naming the mode.
TEST(CommandValidatorTest, RejectsUnknownMode) {
  CommandValidator validator(ArmGeometry::a465());
  Cmd command = cartesian(1, 0.45, 0.0, 0.20);
  command.mode = 0;
  EXPECT_TRUE(rejected_with(validator.validate(command, ready_joints()), "unknown mode 0"));
  command.sequence = 2;
  command.mode = 8;
  EXPECT_TRUE(rejected_with(validator.validate(command, ready_joints()), "unknown mode 8"));
  command.sequence = 3;
  command.mode = -1;
  EXPECT_TRUE(rejected_with(validator.validate(command, ready_joints()), "unknown mode -1"));
}

// An unknown gripper action, and a gripper-only command that keeps the gripper, are rejected.
TEST(CommandValidatorTest, RejectsBadGripperActions) {
  CommandValidator validator(ArmGeometry::a465());
  Cmd command = cartesian(1, 0.45, 0.0, 0.20);
  command.gripper = 3;
  EXPECT_TRUE(
      rejected_with(validator.validate(command, ready_joints()), "unknown gripper action 3"));

  Cmd grip{};
  grip.sequence = 2;
  grip.mode = Cmd::MODE_GRIPPER_ONLY;
  grip.gripper = Cmd::GRIPPER_KEEP;
  grip.speed = 0.5;
  grip.sender = "test";
  EXPECT_TRUE(
      rejected_with(validator.validate(grip, ready_joints()), "gripper-only command with KEEP"));
  grip.sequence = 3;
  grip.gripper = Cmd::GRIPPER_CLOSE;
  const ValidationResult closed = validator.validate(grip, ready_joints());
  ASSERT_TRUE(closed.target) << closed.reason;
  EXPECT_FALSE(closed.target->moves_arm());
}

}  // namespace
}  // namespace sg::arm
