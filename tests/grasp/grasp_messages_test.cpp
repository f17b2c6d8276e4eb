// The grasp machine's values as LCM messages: every field carried across (the command's answer
// too), malformed trajectories refused with the reason.

#include "grasp/grasp_messages.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sg::grasp {
namespace {

using stereograsp::arm_cmd_t;
using stereograsp::arm_status_t;
using stereograsp::trajectory_t;

trajectory_t three_points() {
  trajectory_t m{};
  m.utime = 1'000'000;
  m.start_utime = 1'250'000;
  m.period_us = 250'000;
  m.num_points = 3;
  m.position = {{0.1, 0.2, 0.3}, {0.4, 0.5, 0.6}, {0.7, 0.8, 0.9}};
  m.position_sigma = {{0.001, 0.002, 0.003}, {0.004, 0.005, 0.006}, {0.007, 0.008, 0.009}};
  m.status = trajectory_t::STATUS_TRACKING;
  return m;
}

// A request becomes an ARM_COMMAND field for field, with the decision's utime and the sender.
TEST(GraspMessages, RequestToArmCommand) {
  ArmRequest r;
  r.sequence = 42;
  r.mode = arm_cmd_t::MODE_CARTESIAN;
  r.position = {0.45, -0.1, 0.2};
  r.rpy = {M_PI, 0.1, -0.2};
  r.gripper = arm_cmd_t::GRIPPER_CLOSE;
  r.speed = 0.3;
  r.source_utime = 7;
  r.target_utime = 9;
  const arm_cmd_t c = to_arm_cmd(r, 5, "trial");
  EXPECT_EQ(c.utime, 5);
  EXPECT_EQ(c.sequence, 42);
  EXPECT_EQ(c.mode, arm_cmd_t::MODE_CARTESIAN);
  EXPECT_EQ(c.position[1], -0.1);
  EXPECT_EQ(c.orientation[0], M_PI);
  EXPECT_EQ(c.orientation[2], -0.2);
  EXPECT_EQ(c.gripper, arm_cmd_t::GRIPPER_CLOSE);
  EXPECT_EQ(c.speed, 0.3);
  EXPECT_EQ(c.source_utime, 7);
  EXPECT_EQ(c.target_utime, 9);
  EXPECT_EQ(c.sender, "trial");
}

// ARM_STATUS's state maps to connected / moving / error, and the numbers are carried over.
TEST(GraspMessages, ArmStatusToView) {
  arm_status_t s{};
  s.state = arm_status_t::STATE_MOVING;
  s.last_executed_sequence = 3;
  s.last_rejected_sequence = 2;
  s.joints[5] = 0.5;
  s.tool_position[2] = 0.25;
  s.interaction_time = 0.78;
  s.gripper = arm_status_t::GRIPPER_CLOSED;
  s.last_received_sequence = 4;
  s.rejection_reason = "arm commanded by 'x'";
  s.driver_start_utime = 1'790'000'000'000'000;
  s.watchdog = "stopped: 'a' silent for 1.62 s";
  ArmView v = arm_view_of(s);
  EXPECT_EQ(v.gripper, arm_status_t::GRIPPER_CLOSED);
  EXPECT_EQ(v.last_received_sequence, 4);
  EXPECT_EQ(v.rejection_reason, "arm commanded by 'x'");
  EXPECT_EQ(v.driver_start_utime, 1'790'000'000'000'000);
  EXPECT_EQ(v.watchdog, "stopped: 'a' silent for 1.62 s");
  EXPECT_TRUE(v.connected);
  EXPECT_TRUE(v.moving);
  EXPECT_FALSE(v.error);
  EXPECT_EQ(v.last_executed_sequence, 3);
  EXPECT_EQ(v.last_rejected_sequence, 2);
  EXPECT_EQ(v.joints[5], 0.5);
  EXPECT_EQ(v.tool.z(), 0.25);
  EXPECT_EQ(v.interaction_time, 0.78);
  s.state = arm_status_t::STATE_DISCONNECTED;
  EXPECT_FALSE(arm_view_of(s).connected);
  s.state = arm_status_t::STATE_ERROR;
  EXPECT_TRUE(arm_view_of(s).error);
}

// GRASP_STATUS carries the enumerations' values; a missing target is NaN.
TEST(GraspMessages, StatusToGraspStatus) {
  GraspStatusView v;
  v.state = GraspState::kHandClosed;
  v.activity = GraspActivity::kGrasping;
  v.last_action = GraspAction::kCloseHand;
  v.outcome = GraspOutcome::kFailed;
  v.message = "why";
  auto m = to_grasp_status(v, 11);
  EXPECT_EQ(m.utime, 11);
  EXPECT_EQ(m.state, stereograsp::grasp_status_t::Q3_HAND_CLOSED);
  EXPECT_EQ(m.activity, stereograsp::grasp_status_t::ACTIVITY_GRASPING);
  EXPECT_EQ(m.last_action, stereograsp::grasp_status_t::A2_CLOSE_HAND);
  EXPECT_EQ(m.outcome, stereograsp::grasp_status_t::OUTCOME_FAILED);
  EXPECT_EQ(m.message, "why");
  EXPECT_TRUE(std::isnan(m.target[0]));
  EXPECT_EQ(m.command_sequence, -1);  // no command yet
  EXPECT_EQ(m.command_result, stereograsp::grasp_status_t::RESULT_NONE);
  v.target = Eigen::Vector3d(0.1, 0.2, 0.3);
  EXPECT_EQ(to_grasp_status(v, 11).target[2], 0.3);
  const CommandRecord refused{12, {CommandResult::kRefusedState, "grasp refused: no track"}};
  m = to_grasp_status(v, 11, refused);
  EXPECT_EQ(m.command_sequence, 12);
  EXPECT_EQ(m.command_result, stereograsp::grasp_status_t::RESULT_REFUSED_STATE);
  EXPECT_EQ(m.command_reason, "grasp refused: no track");
}

// The machine's command results are grasp_status_t's RESULT_* values.
TEST(GraspMessages, CommandResultsAreTheMessagesConstants) {
  using S = stereograsp::grasp_status_t;
  EXPECT_EQ(static_cast<int8_t>(CommandResult::kNone), S::RESULT_NONE);
  EXPECT_EQ(static_cast<int8_t>(CommandResult::kAccepted), S::RESULT_ACCEPTED);
  EXPECT_EQ(static_cast<int8_t>(CommandResult::kRefusedNotNewer), S::RESULT_REFUSED_NOT_NEWER);
  EXPECT_EQ(static_cast<int8_t>(CommandResult::kRefusedUnknownCommand),
            S::RESULT_REFUSED_UNKNOWN_COMMAND);
  EXPECT_EQ(static_cast<int8_t>(CommandResult::kRefusedBadArgument),
            S::RESULT_REFUSED_BAD_ARGUMENT);
  EXPECT_EQ(static_cast<int8_t>(CommandResult::kRefusedState), S::RESULT_REFUSED_STATE);
}

// A well-formed trajectory becomes a path with its times and points.
TEST(GraspMessages, TrajectoryToPath) {
  const auto p = path_from(three_points());
  ASSERT_TRUE(p);
  EXPECT_EQ(p->utime, 1'000'000);
  EXPECT_EQ(p->start_utime, 1'250'000);
  EXPECT_EQ(p->period_us, 250'000);
  ASSERT_EQ(p->points.size(), 3u);
  EXPECT_EQ(p->points[2].y(), 0.8);
  ASSERT_EQ(p->sigmas.size(), 3u);
  EXPECT_EQ(p->sigmas[1], Eigen::Vector3d(0.004, 0.005, 0.006));
  EXPECT_FALSE(p->lost);
}

// Malformed trajectories are refused with the reason; a lost one may carry NaNs.
TEST(GraspMessages, MalformedTrajectoriesAreRefused) {
  std::string why;
  trajectory_t m = three_points();
  m.period_us = 0;
  EXPECT_FALSE(path_from(m, &why));
  EXPECT_EQ(why, "period 0 us");
  m = three_points();
  m.num_points = 4;
  EXPECT_FALSE(path_from(m, &why));
  EXPECT_EQ(why, "num_points 4 for 3 points");
  m = three_points();
  m.position[1][2] = std::nan("");
  EXPECT_FALSE(path_from(m, &why));
  EXPECT_EQ(why, "point 1 is not 3 finite numbers");
  m.position[1] = {0.1, 0.2};
  EXPECT_FALSE(path_from(m, &why));
  m = three_points();
  m.position_sigma.pop_back();
  EXPECT_FALSE(path_from(m, &why));
  EXPECT_EQ(why, "2 sigmas for 3 points");
  for (const double bad : {-0.001, std::nan(""), HUGE_VAL}) {
    m = three_points();
    m.position_sigma[2][0] = bad;
    EXPECT_FALSE(path_from(m, &why)) << bad;
    EXPECT_EQ(why, "sigma 2 is not 3 finite numbers >= 0") << bad;
  }
  m = three_points();
  m.position[1] = {0.1, 0.2};
  m.status = trajectory_t::STATUS_LOST;
  const auto lost = path_from(m, &why);
  ASSERT_TRUE(lost);
  EXPECT_TRUE(lost->lost);
  EXPECT_EQ(lost->points.size(), 1u);
}

}  // namespace
}  // namespace sg::grasp
