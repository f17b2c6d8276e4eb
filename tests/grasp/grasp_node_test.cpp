// sg-grasp's logic without the bus (GraspNode): the per-sender sequence check and the range
// checks of GRASP_COMMAND, the answer to every command on GRASP_STATUS (command_sequence,
// command_result, command_reason), at most one ARM_COMMAND per poll with the newest trajectory's
// utime, and GRASP_STATUS on a change and once per status period. The ball is still at
// (0.45, 0, 0.10) m; the arm is at its ready pose.

#include "grasp/grasp_node.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace sg::grasp {
namespace {

using stereograsp::arm_cmd_t;
using stereograsp::arm_status_t;
using stereograsp::grasp_command_t;
using stereograsp::grasp_status_t;
using stereograsp::trajectory_t;

constexpr int64_t kSecond = 1'000'000;
constexpr int64_t kT0 = 1'790'000'000 * kSecond;
constexpr double kPeriod = 0.25;  // s between GRASP_STATUS messages

/// A node, an arm at the ready pose and a clock.
struct Rig {
  Rig() : node(ArmGeometry::a465(), GraspSettings{}, 100, kPeriod) {
    arm.state = arm_status_t::STATE_IDLE;
    const double ready[6] = {0, 0, std::numbers::pi / 2, 0, std::numbers::pi / 2, 0};
    for (int i = 0; i < 6; ++i) arm.joints[i] = ready[i];
    const Eigen::Vector3d tool =
        arm::forward_kinematics(ArmGeometry::a465(), Eigen::Map<const Joints>(ready)).translation();
    for (int i = 0; i < 3; ++i) arm.tool_position[i] = tool[i];
    arm.last_executed_sequence = arm.last_rejected_sequence = -1;
  }

  /// A trajectory made at `now`: the ball held still at (0.45, 0, 0.10), 16 points at 4 Hz.
  trajectory_t trajectory() const {
    trajectory_t m{};
    m.utime = now;
    m.source_utime = now - 50'000;
    m.period_us = 250'000;
    m.start_utime = now + m.period_us;
    m.num_points = 16;
    m.position.assign(16, std::vector<double>{0.45, 0.0, 0.10});
    m.status = trajectory_t::STATUS_TRACKING;
    return m;
  }
  void feed() { EXPECT_EQ(node.on_trajectory(trajectory(), now), ""); }
  void connect() { node.on_arm_status(arm, now); }
  void executed(const arm_cmd_t& c) {
    arm.last_executed_sequence = c.sequence;
    node.on_arm_status(arm, now);
  }
  const CommandRecord& command(int8_t command, int64_t sequence, double standoff = 0,
                               const std::string& sender = "test") {
    grasp_command_t m{};
    m.utime = now;
    m.sequence = sequence;
    m.command = command;
    m.standoff = standoff;
    m.sender = sender;
    return node.on_command(m, now);
  }
  GraspNode::Output poll() { return node.poll(now); }
  void advance(double seconds) { now += std::llround(seconds * kSecond); }

  GraspNode node;
  arm_status_t arm{};
  int64_t now = kT0;
};

// A command whose sequence is not newer than its sender's last is refused, and the machine does
// not see it; each sender has its own sequence.
TEST(GraspNodeTest, RefusesCommandsNotNewerThanTheSendersLast) {
  Rig rig;
  rig.connect();
  rig.feed();
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_TRACK, 5).reply.result, CommandResult::kAccepted);
  EXPECT_EQ(rig.node.machine().status().activity, GraspActivity::kTracking);
  const CommandRecord& again = rig.command(grasp_command_t::COMMAND_HOME, 5);
  EXPECT_EQ(again.sequence, 5);
  EXPECT_EQ(again.reply.result, CommandResult::kRefusedNotNewer);
  EXPECT_EQ(again.reply.reason, "sequence 5 from 'test' not newer than 5");
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_HOME, 4).reply.result,
            CommandResult::kRefusedNotNewer);
  EXPECT_EQ(rig.node.machine().status().activity, GraspActivity::kTracking);  // not homing
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_HOME, 1, 0, "other").reply.result,
            CommandResult::kAccepted);
  EXPECT_EQ(rig.node.machine().status().activity, GraspActivity::kHoming);
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_TRACK, 6).reply.result, CommandResult::kAccepted);
}

// An unknown command and a stand-off that is not finite in 0..0.5 m are refused before the
// machine; a refused command still counts as its sender's last.
TEST(GraspNodeTest, RangeChecks) {
  Rig rig;
  rig.connect();
  rig.feed();
  EXPECT_EQ(rig.command(0, 1).reply.result, CommandResult::kRefusedUnknownCommand);
  EXPECT_EQ(rig.command(6, 2).reply.reason, "unknown command 6");
  int64_t sequence = 10;
  for (double standoff : {-0.01, 0.51, std::nan(""), std::numeric_limits<double>::infinity()}) {
    SCOPED_TRACE(standoff);
    const CommandRecord& r = rig.command(grasp_command_t::COMMAND_TRACK, ++sequence, standoff);
    EXPECT_EQ(r.reply.result, CommandResult::kRefusedBadArgument);
    EXPECT_NE(r.reply.reason.find("outside 0..0.5 m"), std::string::npos) << r.reply.reason;
  }
  EXPECT_EQ(rig.node.machine().status().activity, GraspActivity::kIdle);
  EXPECT_EQ(rig.command(6, 2).reply.result, CommandResult::kRefusedNotNewer);
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_TRACK, 20, 0.5).reply.result,
            CommandResult::kAccepted);
  EXPECT_EQ(rig.node.machine().status().activity, GraspActivity::kTracking);
}

// GRASP_STATUS answers every command at once: its sequence and result, and the machine's own
// refusal (a grasp without a track) with its reason; -1 and RESULT_NONE before any command.
TEST(GraspNodeTest, StatusCarriesTheCommandsResult) {
  Rig rig;
  rig.connect();
  GraspNode::Output first = rig.poll();
  ASSERT_TRUE(first.status.has_value());
  EXPECT_EQ(first.status->command_sequence, -1);
  EXPECT_EQ(first.status->command_result, grasp_status_t::RESULT_NONE);
  EXPECT_EQ(first.status->command_reason, "");
  rig.advance(0.01);
  rig.command(grasp_command_t::COMMAND_GRASP, 7);  // no trajectory yet
  GraspNode::Output refused = rig.poll();
  ASSERT_TRUE(refused.status.has_value());
  EXPECT_EQ(refused.status->command_sequence, 7);
  EXPECT_EQ(refused.status->command_result, grasp_status_t::RESULT_REFUSED_STATE);
  EXPECT_EQ(refused.status->command_reason, "grasp refused: no fresh track of the object");
  rig.advance(0.01);
  rig.command(grasp_command_t::COMMAND_GRASP, 7);  // the same refusal text, a replay
  GraspNode::Output replay = rig.poll();
  ASSERT_TRUE(replay.status.has_value());
  EXPECT_EQ(replay.status->command_result, grasp_status_t::RESULT_REFUSED_NOT_NEWER);
  rig.advance(0.01);
  rig.feed();
  rig.command(grasp_command_t::COMMAND_GRASP, 8);
  GraspNode::Output accepted = rig.poll();
  ASSERT_TRUE(accepted.status.has_value());
  EXPECT_EQ(accepted.status->command_sequence, 8);
  EXPECT_EQ(accepted.status->command_result, grasp_status_t::RESULT_ACCEPTED);
  EXPECT_EQ(accepted.status->command_reason, "");
  EXPECT_EQ(accepted.status->activity, grasp_status_t::ACTIVITY_GRASPING);
}

// A reason is short printable ASCII whatever the sender's name holds.
TEST(GraspNodeTest, ReasonIsShortAscii) {
  Rig rig;
  const std::string sender = "b\xC3\xA9" + std::string(300, 'x');
  rig.command(grasp_command_t::COMMAND_TRACK, 2, 0, sender);
  const CommandRecord& r = rig.command(grasp_command_t::COMMAND_TRACK, 1, 0, sender);
  EXPECT_EQ(r.reply.result, CommandResult::kRefusedNotNewer);
  EXPECT_EQ(r.reply.reason.size(), GraspNode::kMaxReason);
  EXPECT_EQ(r.reply.reason.substr(0, 22), "sequence 1 from 'b??xx");
}

// At most kMaxSenders senders are remembered: the longest silent is forgotten first.
TEST(GraspNodeTest, RemembersABoundedNumberOfSenders) {
  Rig rig;
  for (std::size_t i = 0; i <= GraspNode::kMaxSenders; ++i) {
    rig.advance(0.001);
    rig.command(grasp_command_t::COMMAND_HOME, 5, 0, "sender " + std::to_string(i));
  }
  rig.advance(0.001);  // sender 0 was forgotten, sender 1 is still known
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_HOME, 5, 0, "sender 0").reply.result,
            CommandResult::kAccepted);
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_HOME, 5, 0, "sender 2").reply.result,
            CommandResult::kRefusedNotNewer);
}

// One ARM_COMMAND per poll: a0 first, nothing while it is in flight, then the tracking move;
// abort then home gives STOP and, after it is executed, HOME, one poll each. The utime is the
// newest trajectory's (the clock's before any).
TEST(GraspNodeTest, OneArmCommandPerPoll) {
  Rig rig;
  rig.connect();
  const GraspNode::Output open = rig.poll();
  ASSERT_TRUE(open.arm_command.has_value());
  EXPECT_EQ(open.arm_command->sequence, 100);
  EXPECT_EQ(open.arm_command->mode, arm_cmd_t::MODE_GRIPPER_ONLY);
  EXPECT_EQ(open.arm_command->utime, kT0);  // no trajectory yet: the clock
  EXPECT_EQ(open.arm_command->sender, "sg-grasp");
  rig.advance(0.1);
  rig.feed();
  const int64_t trajectory_utime = rig.now;
  rig.command(grasp_command_t::COMMAND_TRACK, 1);
  EXPECT_FALSE(rig.poll().arm_command.has_value());  // a0 in flight
  rig.advance(0.7);
  rig.executed(*open.arm_command);
  const GraspNode::Output move = rig.poll();
  ASSERT_TRUE(move.arm_command.has_value()) << rig.node.machine().status().message;
  EXPECT_EQ(move.arm_command->sequence, 101);
  EXPECT_EQ(move.arm_command->mode, arm_cmd_t::MODE_CARTESIAN);
  EXPECT_EQ(move.arm_command->utime, trajectory_utime);
  EXPECT_NEAR(move.arm_command->position[2], 0.20, 1e-9);  // the stand-off above the ball
  EXPECT_FALSE(rig.poll().arm_command.has_value());
  rig.command(grasp_command_t::COMMAND_ABORT, 2);
  rig.command(grasp_command_t::COMMAND_HOME, 3);
  const GraspNode::Output stop = rig.poll();
  ASSERT_TRUE(stop.arm_command.has_value());
  EXPECT_EQ(stop.arm_command->mode, arm_cmd_t::MODE_STOP);
  EXPECT_FALSE(rig.poll().arm_command.has_value());  // the STOP in flight
  rig.executed(*stop.arm_command);
  const GraspNode::Output home = rig.poll();
  ASSERT_TRUE(home.arm_command.has_value());
  EXPECT_EQ(home.arm_command->mode, arm_cmd_t::MODE_HOME);
  EXPECT_EQ(home.arm_command->sequence, 103);
}

// GRASP_STATUS goes out on the first poll, on a change of the summary (with the summary for the
// log), and otherwise once per status period; also when the clock went back.
TEST(GraspNodeTest, StatusOnChangeAndOnPeriod) {
  Rig rig;
  const GraspNode::Output first = rig.poll();
  ASSERT_TRUE(first.status.has_value());
  EXPECT_EQ(first.status->utime, kT0);
  EXPECT_EQ(first.changed_summary, "q0 hand opened, idle, last none, outcome none");
  rig.advance(0.1);
  EXPECT_FALSE(rig.poll().status.has_value());
  rig.advance(0.149);
  EXPECT_FALSE(rig.poll().status.has_value());
  rig.advance(0.001);  // 0.25 s after the last
  const GraspNode::Output periodic = rig.poll();
  ASSERT_TRUE(periodic.status.has_value());
  EXPECT_EQ(periodic.changed_summary, "");
  rig.advance(0.05);
  rig.connect();  // the machine sends a0: the last action changes
  const GraspNode::Output changed = rig.poll();
  ASSERT_TRUE(changed.status.has_value());
  EXPECT_EQ(changed.status->last_action, grasp_status_t::A0_OPEN_HAND);
  EXPECT_EQ(changed.changed_summary, "q0 hand opened, idle, last a0 open hand, outcome none");
  rig.advance(0.2);
  EXPECT_FALSE(rig.poll().status.has_value());  // 0.2 s after the change
  rig.advance(-10.0);                           // the clock stepped back
  EXPECT_TRUE(rig.poll().status.has_value());
}

// A malformed trajectory is ignored with the reason, and its utime does not date the next
// command (a refused message leaves nothing behind).
TEST(GraspNodeTest, MalformedTrajectoryIsIgnored) {
  Rig rig;
  trajectory_t m = rig.trajectory();
  m.period_us = 0;
  m.utime -= kSecond;
  EXPECT_EQ(rig.node.on_trajectory(m, rig.now), "period 0 us (1 ms to 60 s)");
  rig.connect();
  const GraspNode::Output open = rig.poll();
  ASSERT_TRUE(open.arm_command.has_value());
  EXPECT_EQ(open.arm_command->utime, rig.now);  // no trajectory yet: the node's time
}

}  // namespace
}  // namespace sg::grasp
