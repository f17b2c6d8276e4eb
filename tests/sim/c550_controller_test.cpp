#include "sim/c550_controller.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "arm_driver/aci.hpp"
#include "arm_driver/units.hpp"

namespace sg::sim {
namespace {

using arm::from_degrees;
using arm::Joints;

Joints degrees(double j1, double j2, double j3, double j4, double j5, double j6) {
  return (Joints() << from_degrees(j1), from_degrees(j2), from_degrees(j3), from_degrees(j4),
          from_degrees(j5), from_degrees(j6))
      .finished();
}

C550Controller a465(C550Params params = {}) {
  return C550Controller(arm::ArmGeometry::a465(), params);
}

// The ready pose points the tool straight down in front of the robot, inside the limits.
TEST(C550Controller, ReadyPoseIsToolDownInFront) {
  const C550Controller c550 = a465();
  EXPECT_TRUE(c550.joints(0).isApprox(degrees(0, 0, 90, 0, 90, 0)));
  const Eigen::Isometry3d tcp = c550.tool_pose(0);
  EXPECT_NEAR(tcp.rotation().col(2).z(), -1.0, 1e-12);
  EXPECT_NEAR(tcp.translation().x(), 0.330, 1e-9);  // flange 0.33 m forward of the waist axis
  EXPECT_NEAR(tcp.translation().y(), 0.0, 1e-9);
  EXPECT_NEAR(tcp.translation().z(), 0.559 - 0.15, 1e-9);  // flange z minus the 0.15 m tool
  EXPECT_FALSE(c550.moving(0));
}

// At SPEED 50 a move takes the slowest joint's time: joint 4, 90 deg at 171/2 deg/s.
TEST(C550Controller, MotionDurationIsSlowestJointAtHalfSpeed) {
  C550Controller c550 = a465();
  const Joints target = degrees(30, -20, 100, 90, 90, 45);
  ASSERT_TRUE(c550.move_joints(target, 10.0));
  const double expected = 90.0 / (171.0 * 0.5);  // joint 1: 30/90, joint 6: 45/85.5, less
  EXPECT_NEAR(c550.settle_time() - 10.0, expected, 1e-12);
  EXPECT_TRUE(c550.moving(10.0 + expected - 1e-6));
  EXPECT_FALSE(c550.moving(10.0 + expected));
  EXPECT_TRUE(c550.joints(10.0 + expected + 1.0).isApprox(target, 1e-15));
}

// SPEED 100 halves the time of the same move.
TEST(C550Controller, SpeedScalesTheDuration) {
  C550Controller c550 = a465();
  ASSERT_TRUE(c550.set_speed(100));
  ASSERT_TRUE(c550.move_joints(degrees(0, 0, 90, 90, 90, 0), 0.0));
  EXPECT_NEAR(c550.settle_time(), 90.0 / 171.0, 1e-12);
}

// Mid-motion the joints are the linear interpolation between start and target.
TEST(C550Controller, JointsMidMotionAreTheLinearInterpolation) {
  C550Controller c550 = a465();
  const Joints start = c550.joints(0);
  const Joints target = degrees(30, -20, 100, 90, 90, 45);
  ASSERT_TRUE(c550.move_joints(target, 2.0));
  const double duration = c550.settle_time() - 2.0;
  const Joints mid = c550.joints(2.0 + 0.4 * duration);
  EXPECT_TRUE(mid.isApprox(start + 0.4 * (target - start), 1e-12));
}

// A new move retargets at once from where the arm is, not from the old target.
TEST(C550Controller, NewMoveRetargetsFromTheCurrentPosition) {
  C550Controller c550 = a465();
  ASSERT_TRUE(c550.move_joints(degrees(90, 0, 90, 0, 90, 0), 0.0));  // 1 s at 90 deg/s
  const Joints halfway = c550.joints(0.5);
  EXPECT_NEAR(arm::to_degrees(halfway[0]), 45.0, 1e-9);
  ASSERT_TRUE(c550.move_joints(degrees(0, 0, 90, 0, 90, 0), 0.5));
  EXPECT_TRUE(c550.joints(0.5).isApprox(halfway, 1e-12));
  EXPECT_NEAR(c550.settle_time(), 0.5 + 45.0 / 90.0, 1e-12);
}

// A joint outside its limits (or not finite) is refused with *** 73 and nothing moves.
TEST(C550Controller, LimitViolationIsRefusedWithoutMotion) {
  C550Controller c550 = a465();
  const Joints before = c550.joints(0);
  const CommandResult result = c550.move_joints(degrees(0, 95, 90, 0, 90, 0), 1.0);
  ASSERT_FALSE(result);
  EXPECT_TRUE(result.error.starts_with("*** 73 JOINT LIMIT: joint 2")) << result.error;
  EXPECT_FALSE(c550.moving(1.0));
  EXPECT_TRUE(c550.joints(5.0).isApprox(before));
  Joints nan = before;
  nan[4] = std::nan("");
  EXPECT_TRUE(c550.move_joints(nan, 1.0).error.starts_with("*** 73 JOINT LIMIT: joint 5"));
  EXPECT_FALSE(c550.moving(1.0));
}

// SPEED outside 1..100 is refused and the speed is unchanged.
TEST(C550Controller, SpeedOutsideRangeIsRefused) {
  C550Controller c550 = a465();
  EXPECT_FALSE(c550.set_speed(0));
  EXPECT_FALSE(c550.set_speed(101));
  EXPECT_EQ(c550.speed_percent(), 50);
}

// A Cartesian move reaches its pose; an unreachable one is refused with *** 72.
TEST(C550Controller, MovePoseReachesThePoseOrIsOutOfRange) {
  C550Controller c550 = a465();
  const Eigen::Vector3d xyz(0.45, 0.10, 0.20), rpy(std::numbers::pi, 0, 0);
  ASSERT_TRUE(c550.move_pose(xyz, rpy, 0.0));
  const Eigen::Isometry3d tcp = c550.tool_pose(c550.settle_time());
  EXPECT_NEAR((tcp.translation() - xyz).norm(), 0.0, 1e-9);
  EXPECT_NEAR(tcp.rotation().col(2).z(), -1.0, 1e-9);
  const CommandResult far = c550.move_pose({3.0, 0, 0.5}, rpy, 10.0);
  ASSERT_FALSE(far);
  EXPECT_TRUE(far.error.starts_with("*** 72 LOCATION OUT OF RANGE")) << far.error;
}

// ABORT stops the arm where it is at that time.
TEST(C550Controller, AbortStopsWhereItIs) {
  C550Controller c550 = a465();
  ASSERT_TRUE(c550.move_joints(degrees(90, 0, 90, 0, 90, 0), 0.0));
  const Joints here = c550.joints(0.25);
  c550.abort(0.25);
  EXPECT_FALSE(c550.moving(0.25));
  EXPECT_TRUE(c550.joints(3.0).isApprox(here, 1e-12));
}

// Delay draws lie in [0.72, 0.84] and repeat for the same seed, differ for another.
TEST(C550Controller, InteractionDelaysAreBoundedAndReproducible) {
  C550Controller a = a465(), b = a465();
  C550Params other;
  other.seed = 2;
  C550Controller c = a465(other);
  double sum = 0;
  int differ = 0;
  for (int i = 0; i < 1000; ++i) {
    const double d = a.interaction_delay();
    EXPECT_GE(d, 0.72);
    EXPECT_LE(d, 0.84);
    EXPECT_EQ(d, b.interaction_delay());
    differ += d != c.interaction_delay();
    sum += d;
  }
  EXPECT_NEAR(sum / 1000, 0.78, 0.005);
  EXPECT_GT(differ, 990);
}

// CLOSE with the ball centre within tolerance of the TCP holds it; the fingers stop on it.
TEST(C550Controller, CloseNearTheBallHoldsIt) {
  C550Controller c550 = a465();
  const Eigen::Vector3d ball = c550.tool_pose(0).translation() + Eigen::Vector3d(0.015, 0, 0);
  c550.close(1.0, ball);
  EXPECT_TRUE(c550.holding());
  EXPECT_NEAR(c550.gripper_opening(1.0 + 0.4), 0.07, 1e-12);     // 2 * ball radius
  EXPECT_NEAR(c550.gripper_opening(1.0 + 0.025), 0.075, 1e-12);  // 0.08 m in 0.4 s
}

// CLOSE with the ball beyond tolerance, or unknown, closes on nothing.
TEST(C550Controller, CloseAwayFromTheBallHoldsNothing) {
  C550Controller c550 = a465();
  const Eigen::Vector3d ball = c550.tool_pose(0).translation() + Eigen::Vector3d(0, 0.025, 0);
  c550.close(1.0, ball);
  EXPECT_FALSE(c550.holding());
  EXPECT_NEAR(c550.gripper_opening(1.4), 0.0, 1e-12);
  c550.open(2.0);
  c550.close(3.0, std::nullopt);
  EXPECT_FALSE(c550.holding());
}

// OPEN releases the ball and opens the fingers fully after gripper_time.
TEST(C550Controller, OpenReleases) {
  C550Controller c550 = a465();
  c550.close(1.0, c550.tool_pose(0).translation());
  ASSERT_TRUE(c550.holding());
  c550.open(2.0);
  EXPECT_FALSE(c550.holding());
  EXPECT_TRUE(c550.moving(2.0));
  EXPECT_NEAR(c550.gripper_opening(2.0 + 0.05), 0.08, 1e-12);  // 0.07 -> 0.08 takes 0.05 s
}

// start_holding powers up with the ball between the fingers, at rest, until the first OPEN; a move
// keeps it; a ball that does not fit the open gripper is refused.
TEST(C550Controller, StartHoldingPowersUpWithTheBallInTheGripper) {
  C550Params params;
  params.start_holding = true;
  C550Controller c550 = a465(params);
  EXPECT_TRUE(c550.holding());
  EXPECT_NEAR(c550.gripper_opening(0), 0.07, 1e-12);  // 2 * ball radius
  EXPECT_FALSE(c550.moving(0));
  ASSERT_TRUE(c550.move_pose({0.45, 0.1, 0.15}, {M_PI, 0, std::atan2(0.1, 0.45) + M_PI}, 1.0));
  EXPECT_TRUE(c550.holding());
  EXPECT_NEAR(c550.gripper_opening(c550.settle_time()), 0.07, 1e-12);
  c550.open(c550.settle_time());
  EXPECT_FALSE(c550.holding());
  EXPECT_FALSE(a465().holding());
  params.ball_radius = 0.045;  // 0.09 m across, the gripper opens 0.08 m
  EXPECT_THROW(a465(params), std::invalid_argument);
}

// Segment memory starts at zero and round-trips a write.
TEST(C550Controller, SegmentMemoryRoundTrips) {
  C550Controller c550 = a465();
  EXPECT_EQ(c550.read_memory(arm::aci::kMemSegment, 7, 100, 3), std::vector<uint8_t>(3, 0));
  const std::vector<uint8_t> data{1, 2, 3, 250};
  c550.write_memory(arm::aci::kMemSegment, 7, 65532, data);
  EXPECT_EQ(c550.read_memory(arm::aci::kMemSegment, 7, 65532, 4), data);
  EXPECT_EQ(c550.read_memory(arm::aci::kMemSegment, 8, 65532, 4), std::vector<uint8_t>(4, 0));
  EXPECT_THROW(c550.write_memory(arm::aci::kMemSegment, 7, 65533, data), std::invalid_argument);
}

// The pointer list reads 16 fixed little-endian pointers and refuses writes; 0x48 reads 0x01.
TEST(C550Controller, PointerListIsReadOnlyAndSessionByteIsOne) {
  C550Controller c550 = a465();
  const std::vector<uint8_t> second = c550.read_memory(arm::aci::kMemPointerList, 0, 4, 4);
  EXPECT_EQ(second, (std::vector<uint8_t>{0x00, 0x01, 0x02, 0x00}));  // 0x00020100
  EXPECT_EQ(c550.read_memory(arm::aci::kMemPointerList, 0, 0, 64).size(), 64u);
  EXPECT_NE(c550.memory_access_error(arm::aci::kMemPointerList, 0, 0, 65, false), "");
  const std::vector<uint8_t> data{1};
  EXPECT_THROW(c550.write_memory(arm::aci::kMemPointerList, 0, 0, data), std::invalid_argument);
  EXPECT_EQ(c550.read_memory(arm::aci::kMemSession, 0, 0, 1), std::vector<uint8_t>{0x01});
  EXPECT_NE(c550.memory_access_error(0x33, 0, 0, 1, false), "");
}

// A command earlier than the last one is a programming error, named.
TEST(C550Controller, TimeGoingBackwardsThrows) {
  C550Controller c550 = a465();
  ASSERT_TRUE(c550.ready(5.0));
  EXPECT_THROW(c550.open(4.0), std::invalid_argument);
}

}  // namespace
}  // namespace sg::sim
