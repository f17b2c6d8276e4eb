// sg-grasp's logic without the bus (GraspNode): the per-sender sequence check and the range
// checks of GRASP_COMMAND, the answer to every command on GRASP_STATUS (command_sequence,
// command_result, command_reason), at most one request per poll with the newest trajectory's
// utime, and GRASP_STATUS on a change and once per status period; nothing sent after a restart
// until commanded, heartbeats every period and one release, none with a stale track or a silent
// ARM_STATUS (reported), a resend as the very same message, and no storm of rejected commands.
// The ball is still at (0.45, 0, 0.10) m; the arm is at its ready pose.

#include "grasp/grasp_node.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

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
    m.position_sigma.assign(16, std::vector<double>{0.001, 0.001, 0.001});
    m.status = trajectory_t::STATUS_TRACKING;
    return m;
  }
  void feed() { EXPECT_EQ(node.on_trajectory(trajectory(), now), ""); }
  void connect() { node.on_arm_status(arm, now); }
  void executed(const arm_cmd_t& c) {
    arm.last_received_sequence = arm.last_executed_sequence = c.sequence;
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
  /// The driver's next ARM_STATUS, unchanged.
  void publish() {
    arm.utime = now;
    node.on_arm_status(arm, now);
  }
  /// Runs the loop for `seconds`: a poll every 10 ms, ARM_STATUS every 100 ms (when `statuses`),
  /// a trajectory every 250 ms (when `trajectories`); the driver receives every request (it
  /// executes none); the outputs in order.
  std::vector<GraspNode::Output> run(double seconds, bool statuses = true,
                                     bool trajectories = true) {
    std::vector<GraspNode::Output> out;
    const int64_t end = now + std::llround(seconds * kSecond);
    for (int64_t step = 0; now < end; ++step) {
      now += 10'000;
      if (statuses && step % 10 == 9) publish();
      if (trajectories && step % 25 == 24) feed();
      out.push_back(poll());
      if (out.back().arm_command) arm.last_received_sequence = out.back().arm_command->sequence;
    }
    return out;
  }
  void advance(double seconds) { now += std::llround(seconds * kSecond); }

  GraspNode node;
  arm_status_t arm{};
  int64_t now = kT0;
};

// A command whose sequence is not newer than its sender's last is refused, and the machine does
// not see it; each sender has its own sequence.
// A resend of the command last answered (the bus lost the answer, or the command) gets the same
// answer again, and is not carried out twice; the same sequence with another command is refused.
TEST(GraspNodeTest, ResendOfTheLastCommandGetsItsAnswerAgain) {
  Rig rig;
  rig.connect();
  rig.feed();
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_TRACK, 5).reply.result, CommandResult::kAccepted);
  rig.run(0.5);
  const CommandRecord& again = rig.command(grasp_command_t::COMMAND_TRACK, 5);
  EXPECT_EQ(again.sequence, 5);
  EXPECT_EQ(again.reply.result, CommandResult::kAccepted);
  const GraspNode::Output out = rig.poll();
  ASSERT_TRUE(out.status) << "the answer is published again at once";
  EXPECT_EQ(out.status->command_sequence, 5);
  EXPECT_EQ(out.status->command_result, grasp_status_t::RESULT_ACCEPTED);
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_HOME, 5).reply.result,
            CommandResult::kRefusedNotNewer);
}

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
  rig.command(grasp_command_t::COMMAND_GRASP, 7);  // a resend: its answer again, not "not newer"
  GraspNode::Output replay = rig.poll();
  ASSERT_TRUE(replay.status.has_value());
  EXPECT_EQ(replay.status->command_sequence, 7);
  EXPECT_EQ(replay.status->command_result, grasp_status_t::RESULT_REFUSED_STATE);
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

// One request per poll: nothing unasked, then the HOME asked for, nothing while it is in flight,
// then the tracking move; abort then home gives STOP and, after it is executed, HOME, one poll
// each. The utime is the newest trajectory's (the clock's before any).
TEST(GraspNodeTest, OneArmCommandPerPoll) {
  Rig rig;
  rig.connect();
  EXPECT_FALSE(rig.poll().arm_command.has_value());  // nothing unasked
  rig.command(grasp_command_t::COMMAND_HOME, 1);
  const GraspNode::Output open = rig.poll();
  ASSERT_TRUE(open.arm_command.has_value());
  EXPECT_EQ(open.arm_command->sequence, 100);
  EXPECT_EQ(open.arm_command->mode, arm_cmd_t::MODE_HOME);
  EXPECT_EQ(open.arm_command->utime, kT0);  // no trajectory yet: the clock
  EXPECT_EQ(open.arm_command->sender, "sg-grasp");
  rig.advance(0.1);
  rig.feed();
  const int64_t trajectory_utime = rig.now;
  rig.command(grasp_command_t::COMMAND_TRACK, 2);
  EXPECT_FALSE(rig.poll().arm_command.has_value());  // HOME in flight
  rig.advance(0.3);
  rig.executed(*open.arm_command);
  const GraspNode::Output move = rig.poll();
  ASSERT_TRUE(move.arm_command.has_value()) << rig.node.machine().status().message;
  EXPECT_EQ(move.arm_command->sequence, 101);
  EXPECT_EQ(move.arm_command->mode, arm_cmd_t::MODE_CARTESIAN);
  EXPECT_EQ(move.arm_command->utime, trajectory_utime);
  EXPECT_NEAR(move.arm_command->position[2], 0.20, 1e-9);  // the stand-off above the ball
  EXPECT_FALSE(rig.poll().arm_command.has_value());
  rig.command(grasp_command_t::COMMAND_ABORT, 3);
  rig.command(grasp_command_t::COMMAND_HOME, 4);
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
  rig.connect();
  rig.command(grasp_command_t::COMMAND_HOME, 1);  // the activity changes
  const GraspNode::Output changed = rig.poll();
  ASSERT_TRUE(changed.status.has_value());
  EXPECT_EQ(changed.status->activity, grasp_status_t::ACTIVITY_HOMING);
  EXPECT_EQ(changed.changed_summary, "q0 hand opened, homing, last none, outcome none");
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
  rig.command(grasp_command_t::COMMAND_HOME, 1);
  const GraspNode::Output open = rig.poll();
  ASSERT_TRUE(open.arm_command.has_value());
  EXPECT_EQ(open.arm_command->utime, rig.now);  // no trajectory yet: the node's time
}

/// The utimes of the heartbeats in `outputs`.
std::vector<int64_t> heartbeat_times(const std::vector<GraspNode::Output>& outputs) {
  std::vector<int64_t> times;
  for (const GraspNode::Output& o : outputs) {
    if (o.lease && o.lease->mode == arm_cmd_t::MODE_HEARTBEAT) times.push_back(o.lease->utime);
  }
  return times;
}

/// How many outputs carry a request (new or resent) / a lease command of `mode`.
int requests(const std::vector<GraspNode::Output>& outputs) {
  int n = 0;
  for (const GraspNode::Output& o : outputs) n += o.arm_command.has_value();
  return n;
}
int leases(const std::vector<GraspNode::Output>& outputs, int8_t mode) {
  int n = 0;
  for (const GraspNode::Output& o : outputs) n += o.lease && o.lease->mode == mode;
  return n;
}

// A restarted sg-grasp, the arm's gripper reported CLOSED and fresh trajectories coming: 3 s of
// the loop send no ARM_COMMAND at all (no request, heartbeat or release), and GRASP_STATUS shows
// q3 hand closed, idle.
TEST(GraspNodeTest, RestartWithTheGripperClosedSendsNothing) {
  Rig rig;
  rig.arm.gripper = arm_status_t::GRIPPER_CLOSED;
  rig.arm.state = arm_status_t::STATE_MOVING;  // from the previous sg-grasp's last command
  rig.arm.last_executed_sequence = 55;
  rig.publish();
  rig.feed();
  const std::vector<GraspNode::Output> out = rig.run(3.0);
  EXPECT_EQ(requests(out), 0);
  EXPECT_EQ(leases(out, arm_cmd_t::MODE_HEARTBEAT) + leases(out, arm_cmd_t::MODE_RELEASE), 0);
  EXPECT_EQ(rig.node.machine().status().state, GraspState::kHandClosed);
  EXPECT_EQ(rig.node.machine().status().activity, GraspActivity::kIdle);
  ASSERT_TRUE(out.front().status.has_value());
  EXPECT_EQ(out.front().status->state, grasp_status_t::Q3_HAND_CLOSED);
}

// While it wants the arm the node sends a MODE_HEARTBEAT every heartbeat period (0.2 s) from the
// first request on: the last request's sequence, gripper KEEP, the machine's speed; when it stops
// wanting it (the STOP executed, the arm at rest) one MODE_RELEASE, then nothing.
TEST(GraspNodeTest, HeartbeatsEveryPeriodThenOneRelease) {
  Rig rig;
  rig.publish();
  rig.feed();
  rig.command(grasp_command_t::COMMAND_TRACK, 1);
  const GraspNode::Output first = rig.poll();
  ASSERT_TRUE(first.arm_command.has_value());
  ASSERT_TRUE(first.lease.has_value());
  EXPECT_EQ(first.lease->mode, arm_cmd_t::MODE_HEARTBEAT);
  EXPECT_EQ(first.lease->sequence, 100);
  EXPECT_EQ(first.lease->gripper, arm_cmd_t::GRIPPER_KEEP);
  EXPECT_DOUBLE_EQ(first.lease->speed, 0.5);
  EXPECT_EQ(first.lease->utime, kT0);
  EXPECT_EQ(first.lease->sender, "sg-grasp");
  rig.arm.last_received_sequence = 100;  // the driver has it (still moving towards it)
  const std::vector<GraspNode::Output> second = rig.run(1.0);
  EXPECT_EQ(heartbeat_times(second),
            (std::vector<int64_t>{kT0 + 200'000, kT0 + 400'000, kT0 + 600'000, kT0 + 800'000,
                                  kT0 + 1'000'000}));
  EXPECT_EQ(requests(second), 0);  // the move still in flight
  rig.command(grasp_command_t::COMMAND_ABORT, 2);
  const GraspNode::Output stop = rig.poll();
  ASSERT_TRUE(stop.arm_command.has_value());
  EXPECT_EQ(stop.arm_command->mode, arm_cmd_t::MODE_STOP);
  rig.executed(*stop.arm_command);
  const GraspNode::Output release = rig.poll();
  ASSERT_TRUE(release.lease.has_value());
  EXPECT_EQ(release.lease->mode, arm_cmd_t::MODE_RELEASE);
  EXPECT_EQ(release.lease->sequence, 101);
  const std::vector<GraspNode::Output> after = rig.run(2.0);
  EXPECT_EQ(requests(after), 0);
  EXPECT_EQ(leases(after, arm_cmd_t::MODE_HEARTBEAT) + leases(after, arm_cmd_t::MODE_RELEASE), 0);
  EXPECT_EQ(rig.node.heartbeats(), 6u);
  EXPECT_EQ(rig.node.releases(), 1u);
}

// While tracking, a trajectory older than max_trajectory_age (1 s) stops the heartbeats (no
// release: the driver's watchdog stops the arm) and GRASP_STATUS says so; they resume with the
// track.
TEST(GraspNodeTest, StaleTrajectoryStopsTheHeartbeats) {
  Rig rig;
  rig.publish();
  rig.feed();
  rig.command(grasp_command_t::COMMAND_TRACK, 1);
  ASSERT_TRUE(rig.poll().arm_command.has_value());
  rig.arm.last_received_sequence = 100;  // the driver has it, the arm on its way
  const int64_t fed = rig.now;
  const std::vector<GraspNode::Output> silent = rig.run(3.0, true, false);
  const std::vector<int64_t> beats = heartbeat_times(silent);
  ASSERT_FALSE(beats.empty());
  EXPECT_LE(beats.back(), fed + 1'000'000);  // none once the track is older than 1 s
  EXPECT_GE(beats.back(), fed + 800'000);
  EXPECT_EQ(leases(silent, arm_cmd_t::MODE_RELEASE), 0);
  EXPECT_EQ(requests(silent), 0);
  EXPECT_EQ(rig.node.machine().arm_need(rig.now), ArmNeed::kSilent);
  std::optional<grasp_status_t> status;
  for (const GraspNode::Output& o : silent) {
    if (o.status) status = o.status;
  }
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->message,
            "no fresh track of the object: heartbeats stopped (the driver's watchdog stops the "
            "arm)");
  rig.feed();
  const GraspNode::Output back = rig.poll();
  ASSERT_TRUE(back.lease.has_value());
  EXPECT_EQ(back.lease->mode, arm_cmd_t::MODE_HEARTBEAT);
}

// No ARM_STATUS for more than 1 s: no request and no heartbeat, GRASP_STATUS says "ARM_STATUS
// silent for 1.3 s"; when statuses return, heartbeats and requests resume and the note goes.
TEST(GraspNodeTest, SilentArmStatusStopsCommandsAndIsReported) {
  Rig rig;
  rig.publish();
  rig.feed();
  rig.command(grasp_command_t::COMMAND_TRACK, 1);
  const GraspNode::Output first = rig.poll();
  ASSERT_TRUE(first.arm_command.has_value());
  rig.executed(*first.arm_command);
  const int64_t heard = rig.now;
  rig.now = heard + 1'300'000;
  rig.feed();
  const GraspNode::Output silent = rig.poll();
  EXPECT_FALSE(silent.arm_command.has_value());
  EXPECT_FALSE(silent.lease.has_value());
  ASSERT_TRUE(silent.status.has_value());  // a change: silent
  EXPECT_EQ(silent.status->message, "ARM_STATUS silent for 1.3 s");
  EXPECT_EQ(silent.changed_summary,
            "q0 hand opened, tracking, last none, outcome none "
            "[ARM_STATUS silent]");
  const std::vector<GraspNode::Output> more = rig.run(1.0, false, true);
  EXPECT_EQ(requests(more), 0);
  EXPECT_EQ(leases(more, arm_cmd_t::MODE_HEARTBEAT) + leases(more, arm_cmd_t::MODE_RELEASE), 0);
  rig.publish();
  const GraspNode::Output back = rig.poll();
  ASSERT_TRUE(back.arm_command.has_value());
  EXPECT_EQ(back.arm_command->sequence, 101);
  ASSERT_TRUE(back.lease.has_value());
  EXPECT_EQ(back.lease->mode, arm_cmd_t::MODE_HEARTBEAT);
  ASSERT_TRUE(back.status.has_value());
  EXPECT_EQ(back.status->message.find("silent"), std::string::npos) << back.status->message;
}

// A request the driver did not receive is resent 0.5 s later as the very same message (sequence,
// utime, target), and GRASP_STATUS counts it ("ARM_COMMAND resent 1").
TEST(GraspNodeTest, ResendIsTheSameMessageAndIsShown) {
  Rig rig;
  rig.publish();
  rig.feed();
  rig.command(grasp_command_t::COMMAND_TRACK, 1);
  const GraspNode::Output first = rig.poll();
  ASSERT_TRUE(first.arm_command.has_value());
  std::vector<GraspNode::Output> out = rig.run(0.49, true, true);
  EXPECT_EQ(requests(out), 0);
  rig.now = kT0 + 500'000;
  const GraspNode::Output again = rig.poll();
  ASSERT_TRUE(again.arm_command.has_value());
  EXPECT_EQ(again.arm_command->sequence, first.arm_command->sequence);
  EXPECT_EQ(again.arm_command->utime, first.arm_command->utime);
  EXPECT_EQ(again.arm_command->target_utime, first.arm_command->target_utime);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(again.arm_command->position[i], first.arm_command->position[i]);
  }
  ASSERT_TRUE(again.status.has_value());
  EXPECT_EQ(again.status->message, "ARM_COMMAND resent 1");
}

// A driver that rejects every request (another sender holds the lease) for 20 s: the node sends
// 8 requests, at 0, 0.35, 0.9, 2.0, 4.1, 8.2, 12.3 and 16.4 s (each rejection seen on the next
// ARM_STATUS, 0.1 s apart, then the back-off 0.25, 0.5, 1, 2, 4, 4, 4 s), heartbeats at 5 Hz,
// and GRASP_STATUS says who commands the arm; the old 44,000-command storm is gone.
TEST(GraspNodeTest, RejectionsDoNotStorm) {
  Rig rig;
  rig.publish();
  rig.feed();
  rig.command(grasp_command_t::COMMAND_TRACK, 1);
  rig.arm.rejection_reason = "arm commanded by 'sg-grasp@lab2:4242'";
  std::vector<int64_t> sent;
  std::optional<grasp_status_t> status;
  for (int step = 0; step < 2000; ++step) {
    const GraspNode::Output o = rig.poll();
    if (o.arm_command) {
      sent.push_back((rig.now - kT0) / 10'000);  // in 10 ms
      rig.arm.last_received_sequence = rig.arm.last_rejected_sequence = o.arm_command->sequence;
    }
    if (o.status) status = o.status;
    rig.now += 10'000;
    if (step % 10 == 9) rig.publish();
    if (step % 25 == 24) rig.feed();
  }
  EXPECT_EQ(sent, (std::vector<int64_t>{0, 35, 90, 200, 410, 820, 1230, 1640}));
  EXPECT_NEAR(static_cast<double>(rig.node.heartbeats()), 100, 1);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->message.rfind("waiting: arm commanded by 'sg-grasp@lab2:4242'", 0), 0u)
      << status->message;
}

// A capture clock 1.5 s behind this host's makes every forecast look stale (older than
// max_trajectory_age): a grasp is refused; with the offset known, the forecast is put on this
// host's clock and the grasp is accepted. A clock 6 s ahead is refused outright (max_time_offset)
// until the offset is known.
TEST(GraspNodeTest, CaptureClockOffsetPutsTheForecastOnThisClock) {
  Rig rig;
  rig.connect();
  auto shifted = [&](int64_t offset) {
    trajectory_t m = rig.trajectory();
    m.utime += offset, m.source_utime += offset, m.start_utime += offset;
    return m;
  };
  EXPECT_EQ(rig.node.on_trajectory(shifted(-1'500'000), rig.now), "");
  const CommandRecord& refused = rig.command(grasp_command_t::COMMAND_GRASP, 1);
  EXPECT_EQ(refused.reply.result, CommandResult::kRefusedState);
  EXPECT_EQ(refused.reply.reason, "grasp refused: no fresh track of the object");
  rig.node.set_capture_clock_offset(-1'500'000);
  EXPECT_EQ(rig.node.on_trajectory(shifted(-1'500'000), rig.now), "");
  EXPECT_EQ(rig.command(grasp_command_t::COMMAND_GRASP, 2).reply.result, CommandResult::kAccepted);

  Rig ahead;
  EXPECT_NE(ahead.node
                .on_trajectory(
                    [&] {
                      trajectory_t m = ahead.trajectory();
                      m.utime += 6 * kSecond, m.source_utime += 6 * kSecond,
                          m.start_utime += 6 * kSecond;
                      return m;
                    }(),
                    ahead.now)
                .find("s from the receiver's clock"),
            std::string::npos);
  ahead.node.set_capture_clock_offset(6 * kSecond);
  trajectory_t m = ahead.trajectory();
  m.utime += 6 * kSecond, m.source_utime += 6 * kSecond, m.start_utime += 6 * kSecond;
  EXPECT_EQ(ahead.node.on_trajectory(m, ahead.now), "");
}

}  // namespace
}  // namespace sg::grasp
