// The grasp state machine (figure 4): its transition table for every state and command, a full
// grasp q0 -> q4 judged a success and a failure, abort from every state, a lost track during the
// approach, no command from a stale or lost trajectory, workspace and table refusals, one request
// in flight, the delay learning and the --no-prediction mode; each command's reply, and the
// precedence of the one-off requests (STOP over a0 over home, lift and back-off); a start that
// sends nothing unasked (q3 when the gripper is reported closed), resends under the same
// sequence, none across a driver restart, a silent ARM_STATUS, the back-off after rejections,
// the commander lease's rejection message and what the machine asks of the lease. Fresh
// trajectories are a synthetic circle (centre (0.45, 0, 0.10) m, radius 0.15 m, 1 rpm as in the
// paper) sampled at 4 Hz.

#include "grasp/grasp_machine.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"

namespace sg::grasp {
namespace {

using arm::forward_kinematics;
using arm::IkResult;
using arm::pose_from_xyz_rpy;
using arm::solve_nearest;

using Cmd = stereograsp::arm_cmd_t;
using Status = stereograsp::arm_status_t;

constexpr double kPi = std::numbers::pi;
constexpr int64_t kSecond = 1'000'000;
constexpr int64_t kT0 = 1'790'000'000 * kSecond;  // an arbitrary epoch time

/// Where the emulated arm powers up: elbow and wrist at 90 degrees.
Joints ready_joints() {
  Joints q;
  q << 0, 0, kPi / 2, 0, kPi / 2, 0;
  return q;
}

/// The ball on the paper's circle at time t, at height z.
Eigen::Vector3d circle(int64_t t, double z = 0.10) {
  const double angle = 2 * kPi * static_cast<double>(t - kT0) / (60.0 * kSecond);
  return {0.45 + 0.15 * std::cos(angle), 0.15 * std::sin(angle), z};
}

/// A prediction made at `utime`: 16 points of the circle at 4 Hz from utime + 250 ms.
PredictedPath circle_path(int64_t utime, double z = 0.10) {
  PredictedPath path;
  path.utime = utime;
  path.period_us = 250'000;
  path.start_utime = utime + path.period_us;
  for (int i = 0; i < 16; ++i) path.points.push_back(circle(path.start_utime + i * 250'000, z));
  return path;
}

/// A path that goes nowhere in particular near `p`: 16 points at p.
PredictedPath still_path(int64_t utime, const Eigen::Vector3d& p) {
  return PredictedPath::hold(p, utime);
}

/// What a request does, for the transition table.
enum class Req { kNone, kStop, kOpen, kHome, kMove, kApproach };

const char* name(Req r) {
  switch (r) {
    case Req::kNone:
      return "none";
    case Req::kStop:
      return "STOP+OPEN";
    case Req::kOpen:
      return "OPEN";
    case Req::kHome:
      return "HOME";
    case Req::kMove:
      return "MOVE";
    case Req::kApproach:
      return "MOVE+CLOSE";
  }
  return "?";
}

Req kind(const std::optional<ArmRequest>& r) {
  if (!r) return Req::kNone;
  if (r->mode == Cmd::MODE_STOP && r->gripper == Cmd::GRIPPER_OPEN) return Req::kStop;
  if (r->mode == Cmd::MODE_GRIPPER_ONLY && r->gripper == Cmd::GRIPPER_OPEN) return Req::kOpen;
  if (r->mode == Cmd::MODE_HOME && r->gripper == Cmd::GRIPPER_KEEP) return Req::kHome;
  if (r->mode == Cmd::MODE_CARTESIAN && r->gripper == Cmd::GRIPPER_KEEP) return Req::kMove;
  if (r->mode == Cmd::MODE_CARTESIAN && r->gripper == Cmd::GRIPPER_CLOSE) return Req::kApproach;
  return Req::kNone;
}

/// A machine, a connected arm at the ready pose with the hand reported open, and a clock. The
/// arm's driver receives every request taken and publishes its status before each take().
struct Rig {
  explicit Rig(GraspSettings s = {}, int8_t gripper = Status::GRIPPER_OPEN)
      : settings(s), machine(geometry, s, 100) {
    arm.connected = true;
    arm.gripper = gripper;
    arm.joints = ready_joints();
    arm.tool = forward_kinematics(geometry, arm.joints).translation();
    machine.on_arm_status(arm, now);
  }

  /// A fresh trajectory (made at now, from a frame captured 50 ms before).
  void feed(double z = 0.10) { machine.on_trajectory(circle_path(now, z), now - 50'000, now); }
  /// A fresh trajectory whose every point carries the 1-sigma error `sigma` per axis.
  void feed_with_sigma(double sigma) {
    PredictedPath path = circle_path(now);
    path.sigmas.assign(path.points.size(), Eigen::Vector3d::Constant(sigma));
    machine.on_trajectory(path, now - 50'000, now);
  }
  void lose() {
    PredictedPath path = circle_path(now);
    path.lost = true;
    machine.on_trajectory(path, now - 50'000, now);
  }
  void advance(double seconds) { now += std::llround(seconds * kSecond); }
  void command(GraspCommand c, double standoff = 0) { machine.on_command(c, standoff, now); }
  std::optional<ArmRequest> take() {
    machine.on_arm_status(arm, now);  // the driver publishes at 10 Hz
    std::optional<ArmRequest> r = machine.take_request(now);
    if (r) arm.last_received_sequence = r->sequence;
    return r;
  }
  const GraspStatusView& status() const { return machine.status(); }

  /// The arm reports `r` executed; a Cartesian target moves the arm there (its inverse
  /// kinematics nearest the current joints).
  void executed(const ArmRequest& r, bool moving = false, double interaction_time = 0) {
    if (r.mode == Cmd::MODE_CARTESIAN) {
      const IkResult ik = solve_nearest(geometry, pose_from_xyz_rpy(r.position, r.rpy), arm.joints);
      if (ik.joints) arm.joints = *ik.joints;
      arm.tool = forward_kinematics(geometry, arm.joints).translation();
    }
    arm.last_executed_sequence = r.sequence;
    if (r.gripper == Cmd::GRIPPER_OPEN) arm.gripper = Status::GRIPPER_OPEN;
    if (r.gripper == Cmd::GRIPPER_CLOSE) arm.gripper = Status::GRIPPER_CLOSED;
    arm.moving = moving;
    if (interaction_time > 0) arm.interaction_time = interaction_time;
    machine.on_arm_status(arm, now);
  }
  /// The driver's next ARM_STATUS, unchanged.
  void publish() { machine.on_arm_status(arm, now); }
  void rejected(const ArmRequest& r) {
    arm.last_rejected_sequence = r.sequence;
    machine.on_arm_status(arm, now);
  }

  /// Takes the next request, which must exist, and reports it executed.
  ArmRequest run(bool moving = false) {
    std::optional<ArmRequest> r = take();
    EXPECT_TRUE(r.has_value()) << status().message;
    if (!r) return {};
    executed(*r, moving);
    return *r;
  }

  ArmGeometry geometry = ArmGeometry::a465();
  GraspSettings settings;
  int64_t now = kT0;
  ArmView arm;
  GraspMachine machine;
};

/// The situations of the transition table, each reached through the public API.
enum class At {
  kQ0Idle,
  kQ0Tracking,
  kQ0Homing,      // HOME asked for, not yet sent
  kQ0BackingOff,  // the back-off not yet sent
  kQ1,            // a1 not yet sent
  kQ2,            // a1 + a2 in flight
  kQ3Grasping,    // a3 not yet sent
  kQ3Idle,        // the arm rejected the lift
  kQ4Grasping,    // lifted, judging
  kQ4Idle,        // judged: success
};

const char* name(At at) {
  switch (at) {
    case At::kQ0Idle:
      return "q0 idle";
    case At::kQ0Tracking:
      return "q0 tracking";
    case At::kQ0Homing:
      return "q0 homing";
    case At::kQ0BackingOff:
      return "q0 backing off";
    case At::kQ1:
      return "q1 grasping";
    case At::kQ2:
      return "q2 grasping";
    case At::kQ3Grasping:
      return "q3 grasping";
    case At::kQ3Idle:
      return "q3 idle";
    case At::kQ4Grasping:
      return "q4 grasping";
    case At::kQ4Idle:
      return "q4 idle";
  }
  return "?";
}

/// Brings `rig` (fresh from its constructor) to `at`, answering every request on the way.
void reach(Rig& rig, At at) {
  ASSERT_EQ(kind(rig.take()), Req::kNone);  // nothing unasked
  rig.advance(0.8);
  rig.feed();
  switch (at) {
    case At::kQ0Idle:
      return;
    case At::kQ0Tracking:
      rig.command(GraspCommand::kTrack);
      return;
    case At::kQ0Homing:
      rig.command(GraspCommand::kHome);
      return;
    default:
      break;
  }
  rig.command(GraspCommand::kGrasp);
  ASSERT_EQ(rig.status().state, GraspState::kApproaching) << rig.status().message;
  if (at == At::kQ1) return;
  if (at == At::kQ0BackingOff) {  // lost, and not back by max_wait after the command
    rig.advance(rig.settings.max_wait);
    rig.publish();
    rig.lose();
    return;
  }
  const std::optional<ArmRequest> approach = rig.take();
  ASSERT_EQ(kind(approach), Req::kApproach) << rig.status().message;
  if (at == At::kQ2) return;
  rig.advance(0.8);
  rig.executed(*approach, true);
  if (at == At::kQ3Grasping) return;
  const std::optional<ArmRequest> lift = rig.take();
  ASSERT_EQ(kind(lift), Req::kMove);
  rig.advance(0.8);
  if (at == At::kQ3Idle) {
    rig.rejected(*lift);
    rig.advance(GraspMachine::kRetryFirst);  // the back-off after the rejection
    return;
  }
  rig.executed(*lift, true);
  if (at == At::kQ4Grasping) return;
  rig.advance(0.3);
  rig.arm.moving = false;
  rig.machine.on_arm_status(rig.arm, rig.now);
  rig.advance(0.1);
  rig.machine.on_measurement(rig.arm.tool, rig.now - 20'000);
}

struct Expect {
  GraspState state;
  GraspActivity activity;
};

const std::vector<At> kEverySituation = {
    At::kQ0Idle, At::kQ0Tracking, At::kQ0Homing, At::kQ0BackingOff, At::kQ1,
    At::kQ2,     At::kQ3Grasping, At::kQ3Idle,   At::kQ4Grasping,   At::kQ4Idle};

// Each situation reached through the public API shows the state and activity the table says.
TEST(GraspMachineTest, SituationsShowTheirStateAndActivity) {
  const std::vector<Expect> expected = {
      {GraspState::kHandOpened, GraspActivity::kIdle},
      {GraspState::kHandOpened, GraspActivity::kTracking},
      {GraspState::kHandOpened, GraspActivity::kHoming},
      {GraspState::kHandOpened, GraspActivity::kBackingOff},
      {GraspState::kApproaching, GraspActivity::kGrasping},
      {GraspState::kGrasping, GraspActivity::kGrasping},
      {GraspState::kHandClosed, GraspActivity::kGrasping},
      {GraspState::kHandClosed, GraspActivity::kIdle},
      {GraspState::kObjectLifted, GraspActivity::kGrasping},
      {GraspState::kObjectLifted, GraspActivity::kIdle},
  };
  for (std::size_t i = 0; i < kEverySituation.size(); ++i) {
    SCOPED_TRACE(name(kEverySituation[i]));
    Rig rig;
    reach(rig, kEverySituation[i]);
    EXPECT_EQ(rig.status().state, expected[i].state) << to_string(rig.status().state);
    EXPECT_EQ(rig.status().activity, expected[i].activity) << to_string(rig.status().activity);
  }
}

// Every situation times every command: the state and activity after the command and the kind of
// request take_request() makes next (a fresh trajectory is always at hand).
TEST(GraspMachineTest, TransitionTable) {
  using S = GraspState;
  using A = GraspActivity;
  struct Row {
    At at;
    GraspCommand command;
    S state;
    A activity;
    Req request;
  };
  const S q0 = S::kHandOpened, q1 = S::kApproaching, q2 = S::kGrasping, q3 = S::kHandClosed,
          q4 = S::kObjectLifted;
  const A idle = A::kIdle, tracking = A::kTracking, grasping = A::kGrasping, homing = A::kHoming,
          backing = A::kBackingOff;
  const GraspCommand track = GraspCommand::kTrack, grasp = GraspCommand::kGrasp,
                     release = GraspCommand::kRelease, abort = GraspCommand::kAbort,
                     home = GraspCommand::kHome;
  const std::vector<Row> table = {
      {At::kQ0Idle, track, q0, tracking, Req::kMove},
      {At::kQ0Idle, grasp, q1, grasping, Req::kApproach},
      {At::kQ0Idle, release, q0, idle, Req::kNone},
      {At::kQ0Idle, abort, q0, idle, Req::kStop},
      {At::kQ0Idle, home, q0, homing, Req::kHome},
      {At::kQ0Tracking, track, q0, tracking, Req::kMove},
      {At::kQ0Tracking, grasp, q1, grasping, Req::kApproach},
      {At::kQ0Tracking, release, q0, tracking, Req::kMove},
      {At::kQ0Tracking, abort, q0, idle, Req::kStop},
      {At::kQ0Tracking, home, q0, homing, Req::kHome},
      {At::kQ0Homing, track, q0, tracking, Req::kMove},
      {At::kQ0Homing, grasp, q1, grasping, Req::kApproach},
      {At::kQ0Homing, release, q0, homing, Req::kHome},
      {At::kQ0Homing, abort, q0, idle, Req::kStop},
      {At::kQ0Homing, home, q0, homing, Req::kHome},
      {At::kQ0BackingOff, track, q0, backing, Req::kMove},
      {At::kQ0BackingOff, grasp, q0, backing, Req::kMove},
      {At::kQ0BackingOff, release, q0, backing, Req::kMove},
      {At::kQ0BackingOff, abort, q0, idle, Req::kStop},
      {At::kQ0BackingOff, home, q0, backing, Req::kMove},
      {At::kQ1, track, q1, grasping, Req::kApproach},
      {At::kQ1, grasp, q1, grasping, Req::kApproach},
      {At::kQ1, release, q1, grasping, Req::kApproach},
      {At::kQ1, abort, q0, idle, Req::kStop},
      {At::kQ1, home, q1, grasping, Req::kApproach},
      {At::kQ2, track, q2, grasping, Req::kNone},
      {At::kQ2, grasp, q2, grasping, Req::kNone},
      {At::kQ2, release, q2, grasping, Req::kNone},
      {At::kQ2, abort, q0, idle, Req::kStop},
      {At::kQ2, home, q2, grasping, Req::kNone},
      {At::kQ3Grasping, track, q3, grasping, Req::kMove},
      {At::kQ3Grasping, grasp, q3, grasping, Req::kMove},
      {At::kQ3Grasping, release, q3, idle, Req::kOpen},
      {At::kQ3Grasping, abort, q0, idle, Req::kStop},
      {At::kQ3Grasping, home, q3, grasping, Req::kMove},
      {At::kQ3Idle, track, q3, idle, Req::kNone},
      {At::kQ3Idle, grasp, q3, idle, Req::kNone},
      {At::kQ3Idle, release, q3, idle, Req::kOpen},
      {At::kQ3Idle, abort, q0, idle, Req::kStop},
      {At::kQ3Idle, home, q3, homing, Req::kHome},
      {At::kQ4Grasping, track, q4, grasping, Req::kNone},
      {At::kQ4Grasping, grasp, q4, grasping, Req::kNone},
      {At::kQ4Grasping, release, q4, idle, Req::kOpen},
      {At::kQ4Grasping, abort, q0, idle, Req::kStop},
      {At::kQ4Grasping, home, q4, grasping, Req::kNone},
      {At::kQ4Idle, track, q4, idle, Req::kNone},
      {At::kQ4Idle, grasp, q4, idle, Req::kNone},
      {At::kQ4Idle, release, q4, idle, Req::kOpen},
      {At::kQ4Idle, abort, q0, idle, Req::kStop},
      {At::kQ4Idle, home, q4, homing, Req::kHome},
  };
  ASSERT_EQ(table.size(), kEverySituation.size() * 5);
  for (const Row& row : table) {
    SCOPED_TRACE(std::string(name(row.at)) + " + " + to_string(row.command));
    Rig rig;
    reach(rig, row.at);
    rig.advance(0.1);
    rig.feed();
    rig.command(row.command);
    EXPECT_EQ(rig.status().state, row.state) << to_string(rig.status().state);
    EXPECT_EQ(rig.status().activity, row.activity) << to_string(rig.status().activity);
    const std::optional<ArmRequest> r = rig.take();
    EXPECT_EQ(kind(r), row.request) << name(kind(r)) << " / " << rig.status().message;
  }
}

// A refused or ignored command says why in the status message.
TEST(GraspMachineTest, RefusedCommandsSayWhy) {
  Rig rig;
  reach(rig, At::kQ0Idle);
  rig.command(GraspCommand::kRelease);
  EXPECT_NE(rig.status().message.find("release ignored"), std::string::npos);
  rig.advance(2.0);  // the trajectory is now stale
  rig.command(GraspCommand::kGrasp);
  EXPECT_EQ(rig.status().state, GraspState::kHandOpened);
  EXPECT_NE(rig.status().message.find("no fresh track"), std::string::npos);
  Rig holding;
  reach(holding, At::kQ4Idle);
  holding.command(GraspCommand::kTrack);
  EXPECT_NE(holding.status().message.find("release the object first"), std::string::npos);
}

// A start sends nothing unasked: no request before the first ARM_STATUS, none after it (the
// hand reported unknown), none for seconds after; the first command's request is sequence 7.
TEST(GraspMachineTest, StartSendsNothingUntilCommanded) {
  GraspMachine machine(ArmGeometry::a465(), {}, 7);
  EXPECT_FALSE(machine.take_request(kT0).has_value());  // no arm status yet
  ArmView arm;
  arm.connected = true;
  arm.joints = ready_joints();
  for (int i = 0; i <= 30; ++i) {  // 3 s of statuses at 10 Hz
    machine.on_arm_status(arm, kT0 + i * 100'000);
    EXPECT_FALSE(machine.take_request(kT0 + i * 100'000).has_value());
    EXPECT_EQ(machine.arm_need(kT0 + i * 100'000), ArmNeed::kNone);
  }
  EXPECT_EQ(machine.status().state, GraspState::kHandOpened);
  EXPECT_EQ(machine.status().activity, GraspActivity::kIdle);
  EXPECT_EQ(machine.status().last_action, GraspAction::kNone);
  EXPECT_EQ(machine.next_action(), NextAction::kNone);
  machine.on_command(GraspCommand::kHome, 0, kT0 + 3'000'000);
  const std::optional<ArmRequest> home = machine.take_request(kT0 + 3'000'000);
  ASSERT_TRUE(home.has_value());
  EXPECT_EQ(home->sequence, 7);
  EXPECT_EQ(home->mode, Cmd::MODE_HOME);
}

// A restart with the gripper reported CLOSED (the arm may hold the ball): q3 hand closed, idle,
// nothing sent; track and grasp are refused, release sends a0 (q0), and only then.
TEST(GraspMachineTest, RestartWithTheGripperClosedIsQ3IdleAndSendsNothing) {
  Rig rig({}, Status::GRIPPER_CLOSED);
  rig.arm.moving = true;  // still moving from the previous sg-grasp's command (sequence 55)
  rig.arm.last_executed_sequence = 55;
  rig.feed();
  for (int i = 0; i < 20; ++i) {
    rig.advance(0.1);
    rig.feed();
    EXPECT_EQ(kind(rig.take()), Req::kNone);
    EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kNone);  // not its motion: no heartbeat
  }
  EXPECT_EQ(rig.status().state, GraspState::kHandClosed);
  EXPECT_EQ(rig.status().activity, GraspActivity::kIdle);
  EXPECT_EQ(rig.machine.on_command(GraspCommand::kTrack, 0, rig.now).result,
            CommandResult::kRefusedState);
  EXPECT_EQ(rig.machine.on_command(GraspCommand::kGrasp, 0, rig.now).result,
            CommandResult::kRefusedState);
  EXPECT_EQ(kind(rig.take()), Req::kNone);
  EXPECT_EQ(rig.machine.on_command(GraspCommand::kRelease, 0, rig.now).result,
            CommandResult::kAccepted);
  const std::optional<ArmRequest> open = rig.take();
  ASSERT_EQ(kind(open), Req::kOpen);
  EXPECT_EQ(open->sequence, 100);
  EXPECT_EQ(rig.status().state, GraspState::kHandOpened);
}

// A track asked for before the first ARM_STATUS, which then reports the gripper CLOSED: q3 idle,
// the track cancelled with a message, nothing sent.
TEST(GraspMachineTest, ClosedGripperAtTheFirstStatusCancelsAnEarlierTrack) {
  GraspMachine machine(ArmGeometry::a465(), {}, 7);
  machine.on_trajectory(circle_path(kT0), kT0 - 50'000, kT0);
  EXPECT_EQ(machine.on_command(GraspCommand::kTrack, 0, kT0).result, CommandResult::kAccepted);
  ArmView arm;
  arm.connected = true;
  arm.joints = ready_joints();
  arm.gripper = Status::GRIPPER_CLOSED;
  machine.on_arm_status(arm, kT0 + 10'000);
  EXPECT_FALSE(machine.take_request(kT0 + 10'000).has_value());
  EXPECT_EQ(machine.status().state, GraspState::kHandClosed);
  EXPECT_EQ(machine.status().activity, GraspActivity::kIdle);
  EXPECT_EQ(machine.status().message,
            "the gripper is reported closed: q3 hand closed, track cancelled (release first)");
}

// Tracking aims at the ball's predicted position at arrival, the stand-off above it, and a
// track command's stand-off replaces the default.
TEST(GraspMachineTest, TrackingAimsAboveThePredictedPosition) {
  Rig rig;
  reach(rig, At::kQ0Idle);
  rig.command(GraspCommand::kTrack);
  const std::optional<ArmRequest> r = rig.take();
  ASSERT_TRUE(r.has_value()) << rig.status().message;
  EXPECT_EQ(r->mode, Cmd::MODE_CARTESIAN);
  EXPECT_EQ(r->gripper, Cmd::GRIPPER_KEEP);
  EXPECT_DOUBLE_EQ(r->speed, 0.5);
  EXPECT_EQ(r->source_utime, rig.now - 50'000);
  EXPECT_GE(r->target_utime, rig.now + std::llround(0.78 * kSecond));
  const Eigen::Vector3d ball = circle(r->target_utime);
  EXPECT_LT((r->position - (ball + Eigen::Vector3d(0, 0, 0.10))).norm(), 0.005);
  ASSERT_TRUE(rig.status().target.has_value());
  EXPECT_TRUE(*rig.status().target == r->position);
  EXPECT_EQ(rig.status().target_utime, r->target_utime);
  EXPECT_EQ(rig.status().state, GraspState::kHandOpened);

  rig.advance(0.8);
  rig.executed(*r);
  rig.feed();
  rig.command(GraspCommand::kTrack, 0.2);
  const std::optional<ArmRequest> higher = rig.take();
  ASSERT_TRUE(higher.has_value()) << rig.status().message;
  EXPECT_LT((higher->position - (circle(higher->target_utime) + Eigen::Vector3d(0, 0, 0.2))).norm(),
            0.005);
}

// A whole grasp: a1 with the close in one request (q2), q3 when executed, a3 straight up by
// `lift`, q4, then success from a measurement at the tool taken after the arm stopped, and a0.
TEST(GraspMachineTest, FullGraspSucceeds) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  rig.run();
  rig.advance(0.8);
  rig.feed();
  rig.command(GraspCommand::kGrasp);
  EXPECT_EQ(rig.status().state, GraspState::kApproaching);
  EXPECT_EQ(rig.status().last_action, GraspAction::kApproachObject);

  const std::optional<ArmRequest> approach = rig.take();
  ASSERT_EQ(kind(approach), Req::kApproach) << rig.status().message;
  const double delay = rig.machine.delay_estimate();
  // The close executes one delay after the motion starts: T >= now + 2 delays.
  EXPECT_GE(approach->target_utime, rig.now + std::llround(2 * delay * kSecond) - 1000);
  EXPECT_LT((approach->position - circle(approach->target_utime)).norm(), 0.005);
  EXPECT_EQ(rig.status().state, GraspState::kGrasping);
  EXPECT_EQ(rig.status().last_action, GraspAction::kCloseHand);
  EXPECT_FALSE(rig.take().has_value());  // in flight

  rig.advance(0.8);
  rig.executed(*approach, true);
  EXPECT_EQ(rig.status().state, GraspState::kHandClosed);
  const std::optional<ArmRequest> lift = rig.take();
  ASSERT_EQ(kind(lift), Req::kMove) << rig.status().message;
  EXPECT_LT((lift->position - (approach->position + Eigen::Vector3d(0, 0, 0.15))).norm(), 1e-12);
  EXPECT_LT((lift->rpy - approach->rpy).norm(), 1e-12);
  EXPECT_EQ(rig.status().last_action, GraspAction::kLiftObject);
  EXPECT_EQ(rig.status().state, GraspState::kHandClosed);

  rig.advance(0.8);
  rig.machine.on_measurement(rig.arm.tool, rig.now - 10'000);  // before the lift: no verdict
  rig.executed(*lift, true);
  EXPECT_EQ(rig.status().state, GraspState::kObjectLifted);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kNone);
  rig.advance(0.3);
  rig.machine.on_measurement(rig.arm.tool, rig.now);  // still moving: no verdict
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kNone);
  rig.advance(0.1);
  rig.arm.moving = false;
  rig.machine.on_arm_status(rig.arm, rig.now);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kNone);  // that measurement was before the stop
  rig.advance(0.25);
  rig.machine.on_measurement(std::nullopt, rig.now);  // not visible: no verdict yet
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kNone);
  rig.advance(0.25);
  rig.machine.on_measurement(rig.arm.tool + Eigen::Vector3d(0.01, 0.02, 0), rig.now);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kSuccess) << rig.status().message;
  EXPECT_EQ(rig.status().activity, GraspActivity::kIdle);
  EXPECT_EQ(rig.status().state, GraspState::kObjectLifted);

  rig.command(GraspCommand::kRelease);
  const std::optional<ArmRequest> open = rig.take();
  EXPECT_EQ(kind(open), Req::kOpen);
  EXPECT_EQ(rig.status().state, GraspState::kHandOpened);
  EXPECT_EQ(rig.status().last_action, GraspAction::kOpenHand);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kSuccess);
}

// A grasp asked for with the arm far away (turned 150 degrees from the ball): the CLOSE would
// come before the arm got there, so the machine first closes in above the ball (gripper kept,
// still q1), then approaches with the CLOSE (q2).
TEST(GraspMachineTest, FarApproachClosesInFirst) {
  Rig rig;
  reach(rig, At::kQ0Idle);
  rig.arm.joints[0] = 150 * kPi / 180;
  rig.arm.tool = forward_kinematics(rig.geometry, rig.arm.joints).translation();
  rig.machine.on_arm_status(rig.arm, rig.now);
  rig.feed();
  rig.command(GraspCommand::kGrasp);
  const std::optional<ArmRequest> closer = rig.take();
  ASSERT_EQ(kind(closer), Req::kMove) << rig.status().message;
  EXPECT_EQ(closer->gripper, Cmd::GRIPPER_KEEP);
  EXPECT_NEAR(closer->position.z(), 0.10 + rig.settings.standoff, 1e-9);
  EXPECT_EQ(rig.status().state, GraspState::kApproaching);
  rig.advance(0.8);
  rig.executed(*closer);
  rig.feed();
  const std::optional<ArmRequest> approach = rig.take();
  ASSERT_EQ(kind(approach), Req::kApproach) << rig.status().message;
  EXPECT_EQ(rig.status().state, GraspState::kGrasping);
}

/// Tracking, then a grasp asked for with a fresh trajectory whose points carry `sigma` per axis.
void grasp_while_tracking(Rig& rig, double sigma) {
  reach(rig, At::kQ0Tracking);
  rig.run();
  rig.advance(0.8);
  rig.feed_with_sigma(sigma);
  rig.command(GraspCommand::kGrasp);
}

// A forecast too unsure for the gripper (2 sigma of 0.02 m per axis is 69 mm > 20 mm) keeps the
// arm tracking above the ball in q1 and says so; a sure one (0.002 m per axis: 2 x sqrt(12e-6 +
// arm 1e-6 + (15.7 mm/s x 0.035 s)^2) = 7.3 mm) sends the approach with the CLOSE.
TEST(GraspMachineTest, WaitsToCloseUntilTheForecastIsSure) {
  Rig rig;
  grasp_while_tracking(rig, 0.02);
  const std::optional<ArmRequest> wait = rig.take();
  ASSERT_EQ(kind(wait), Req::kMove) << rig.status().message;
  EXPECT_NEAR(wait->position.z(), 0.10 + rig.settings.standoff, 0.002);
  EXPECT_EQ(rig.status().state, GraspState::kApproaching);
  EXPECT_EQ(rig.status().message.rfind("waiting to close: 2.0 sigma 69.", 0), 0u)
      << rig.status().message;
  EXPECT_NE(rig.status().message.find("> 20.0 mm tolerance (8.0 s left)"), std::string::npos)
      << rig.status().message;
  rig.advance(0.8);
  rig.executed(*wait);
  rig.feed_with_sigma(0.002);
  const std::optional<ArmRequest> approach = rig.take();
  ASSERT_EQ(kind(approach), Req::kApproach) << rig.status().message;
  EXPECT_EQ(rig.status().state, GraspState::kGrasping);
  EXPECT_EQ(rig.status().message, "closing: 2.0 sigma 7.3 mm <= 20.0 mm tolerance");
}

// A forecast that never becomes sure: the machine tracks until max_wait after the grasp command,
// then closes on its best guess and says so (the operator's grasp is carried out, late).
TEST(GraspMachineTest, ClosesOnAGuessAfterMaxWait) {
  GraspSettings s;
  s.max_wait = 3.0;
  Rig rig(s);
  grasp_while_tracking(rig, 0.05);
  for (int i = 0; i < 3; ++i) {  // at 0, 0.8 and 1.6 s
    const std::optional<ArmRequest> wait = rig.take();
    ASSERT_EQ(kind(wait), Req::kMove) << i << ": " << rig.status().message;
    rig.advance(0.8);
    rig.executed(*wait);
    rig.feed_with_sigma(0.05);
  }
  rig.advance(0.8);  // 3.2 s after the command
  rig.feed_with_sigma(0.05);
  const std::optional<ArmRequest> guess = rig.take();
  ASSERT_EQ(kind(guess), Req::kApproach) << rig.status().message;
  EXPECT_EQ(rig.status().message.rfind("closing on a guess after 3.0 s: 2.0 sigma ", 0), 0u)
      << rig.status().message;
}

// A confidence of 0 closes at once, however unsure the forecast (the machine before issue 17).
TEST(GraspMachineTest, ConfidenceZeroClosesAtOnce) {
  GraspSettings s;
  s.confidence = 0;
  Rig rig(s);
  grasp_while_tracking(rig, 0.05);
  EXPECT_EQ(kind(rig.take()), Req::kApproach) << rig.status().message;
}

/// A prediction made at `utime` of a ball that turned back at `utime`: it retraces the circle.
PredictedPath turned_path(int64_t utime) {
  PredictedPath path = circle_path(utime);
  for (int i = 0; i < 16; ++i) path.points[i] = circle(2 * utime - (path.start_utime + i * 250'000));
  return path;
}

/// q2 with the approach in flight, sent from sure forecasts (1 mm per axis): the approach.
ArmRequest approach_in_flight(Rig& rig) {
  grasp_while_tracking(rig, 0.001);
  const std::optional<ArmRequest> approach = rig.take();
  EXPECT_EQ(kind(approach), Req::kApproach) << rig.status().message;
  EXPECT_EQ(rig.status().state, GraspState::kGrasping);
  return approach.value_or(ArmRequest{});
}

// A turn seen 0.25 s after the approach went out (the ball retraces the circle: at T it is
// about 2 x 15.7 mm/s x 1.3 s = 41 mm from the aim) sends a re-planned approach at once, under a
// new sequence, aimed at the turned path; the old approach's answer changes nothing, the new
// one's moves q2 to q3.
TEST(GraspMachineTest, TurnAfterTheApproachBeganReplansIt) {
  Rig rig;
  const ArmRequest first = approach_in_flight(rig);
  rig.advance(0.25);
  const PredictedPath turned = turned_path(rig.now);
  rig.machine.on_trajectory(turned, rig.now - 50'000, rig.now);

  const std::optional<ArmRequest> again = rig.take();

  ASSERT_EQ(kind(again), Req::kApproach) << rig.status().message;
  EXPECT_EQ(again->sequence, first.sequence + 1);
  EXPECT_LT((again->position - *turned.at(again->target_utime)).norm(), 1e-9);
  const double moved = (*turned.at(first.target_utime) - first.position).norm();
  EXPECT_GT(moved, 0.030);
  const std::string expected = "re-planned (request " + std::to_string(first.sequence) +
                               "): the ball at T moved ";
  EXPECT_EQ(rig.status().message.rfind(expected, 0), 0u) << rig.status().message;
  EXPECT_EQ(rig.status().state, GraspState::kGrasping);
  EXPECT_EQ(rig.machine.replans(), 1u);
  rig.advance(0.6);
  rig.executed(first);  // the driver ran its motion; its CLOSE gave way
  rig.arm.gripper = Status::GRIPPER_OPEN;
  rig.publish();
  EXPECT_EQ(rig.status().state, GraspState::kGrasping);
  rig.advance(0.8);
  rig.executed(*again);
  EXPECT_EQ(rig.status().state, GraspState::kHandClosed);
  EXPECT_EQ(kind(rig.take()), Req::kMove);  // the lift
}

// No re-plan from a newer forecast that agrees with the approach, nor from a turn seen once the
// CLOSE may be on the line (0.7 s after the approach, past 0.78 - 0.15 s), nor from the same
// trajectory again.
TEST(GraspMachineTest, NoReplanWhenTheForecastAgreesOrTheCloseMayHaveGone) {
  Rig rig;
  approach_in_flight(rig);
  rig.advance(0.25);
  rig.feed_with_sigma(0.001);
  EXPECT_EQ(kind(rig.take()), Req::kNone) << rig.status().message;
  rig.advance(0.45);
  rig.machine.on_trajectory(turned_path(rig.now), rig.now - 50'000, rig.now);
  EXPECT_EQ(kind(rig.take()), Req::kNone) << rig.status().message;
  EXPECT_EQ(rig.machine.replans(), 0u);
  EXPECT_EQ(rig.status().state, GraspState::kGrasping);
}

// A forecast that no longer makes the close sure (2 sigma of 0.02 m per axis at T) re-plans the
// approach into tracking above the ball, back in q1 and waiting to close.
TEST(GraspMachineTest, DoubtAfterTheApproachBeganReturnsToWaiting) {
  Rig rig;
  const ArmRequest first = approach_in_flight(rig);
  rig.advance(0.25);
  rig.feed_with_sigma(0.02);

  const std::optional<ArmRequest> wait = rig.take();

  ASSERT_EQ(kind(wait), Req::kMove) << rig.status().message;
  EXPECT_NEAR(wait->position.z(), 0.10 + rig.settings.standoff, 0.002);
  EXPECT_EQ(rig.status().state, GraspState::kApproaching);
  const std::string expected = "re-planned (request " + std::to_string(first.sequence) +
                               "): at T 2.0 sigma 69.";
  EXPECT_EQ(rig.status().message.rfind(expected, 0), 0u) << rig.status().message;
  EXPECT_NE(rig.status().message.find("; waiting to close: 2.0 sigma 69."), std::string::npos)
      << rig.status().message;
}

// A re-plan that came too late: the first approach's CLOSE went out and the hand is reported
// closed when the re-planned tracking move is executed. q1 opens the hand (a0) before it
// approaches again.
TEST(GraspMachineTest, ReplanTooLateOpensTheHandBeforeTheNextApproach) {
  Rig rig;
  const ArmRequest first = approach_in_flight(rig);
  rig.advance(0.25);
  rig.feed_with_sigma(0.02);
  const std::optional<ArmRequest> wait = rig.take();
  ASSERT_EQ(kind(wait), Req::kMove) << rig.status().message;
  rig.advance(0.6);
  rig.executed(first);  // with its CLOSE: gripper CLOSED
  rig.advance(0.8);
  rig.executed(*wait);
  ASSERT_EQ(rig.arm.gripper, Status::GRIPPER_CLOSED);
  rig.feed_with_sigma(0.001);

  const std::optional<ArmRequest> open = rig.take();

  EXPECT_EQ(kind(open), Req::kOpen) << rig.status().message;
  EXPECT_EQ(rig.status().state, GraspState::kApproaching);
  rig.advance(0.8);
  rig.executed(*open);
  rig.feed_with_sigma(0.001);
  EXPECT_EQ(kind(rig.take()), Req::kApproach) << rig.status().message;
}

// Re-plans are bounded: with a turn in every trajectory (the ball reverses every 0.25 s), at
// most max_replans (3) a grasp; then the approach in flight stands.
TEST(GraspMachineTest, ReplansAreBoundedPerGrasp) {
  Rig rig;
  approach_in_flight(rig);
  bool turned = false;
  for (int i = 0; i < 6; ++i) {
    rig.advance(0.25);
    turned = !turned;
    rig.machine.on_trajectory(turned ? turned_path(rig.now) : circle_path(rig.now),
                              rig.now - 50'000, rig.now);
    const std::optional<ArmRequest> r = rig.take();
    EXPECT_EQ(kind(r), i < 3 ? Req::kApproach : Req::kNone) << i << ": " << rig.status().message;
  }
  EXPECT_EQ(rig.machine.replans(), 3u);
}

// After the lift, the ball measured far from the tool for judge_time means the grasp failed; the
// message gives the nearest distance seen.
TEST(GraspMachineTest, FullGraspFailsWhenTheBallIsNotAtTheTool) {
  Rig rig;
  reach(rig, At::kQ4Grasping);
  rig.advance(0.5);
  rig.arm.moving = false;
  rig.machine.on_arm_status(rig.arm, rig.now);
  rig.advance(0.25);
  rig.machine.on_measurement(rig.arm.tool + Eigen::Vector3d(0, 0, -0.30), rig.now);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kNone);  // one sighting could be something else
  rig.advance(2.9);  // past judge_time (3 s) since the arm stopped
  rig.machine.on_measurement(rig.arm.tool + Eigen::Vector3d(0, 0, -0.40), rig.now);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kFailed);
  EXPECT_EQ(rig.status().activity, GraspActivity::kIdle);
  EXPECT_EQ(rig.status().state, GraspState::kObjectLifted);
  EXPECT_NE(rig.status().message.find("0.300 m"), std::string::npos) << rig.status().message;
}

// After the lift, a stray sighting far from the tool (another red thing while the gripper hides
// the ball) does not fail a grasp that a later sighting at the tool confirms.
TEST(GraspMachineTest, StraySightingAfterTheLiftDoesNotFailTheGrasp) {
  Rig rig;
  reach(rig, At::kQ4Grasping);
  rig.advance(0.5);
  rig.arm.moving = false;
  rig.machine.on_arm_status(rig.arm, rig.now);
  rig.advance(0.1);
  rig.machine.on_measurement(rig.arm.tool + Eigen::Vector3d(0.5, 0, 0), rig.now);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kNone);
  rig.advance(0.1);
  rig.machine.on_measurement(rig.arm.tool + Eigen::Vector3d(0.004, 0, 0), rig.now);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kSuccess);
  EXPECT_EQ(rig.status().activity, GraspActivity::kIdle);
  EXPECT_NE(rig.status().message.find("0.004 m"), std::string::npos) << rig.status().message;
}

// After the lift, no visible ball within judge_time of the arm stopping is a failure.
TEST(GraspMachineTest, BallNotSeenAfterTheLiftFails) {
  Rig rig;
  reach(rig, At::kQ4Grasping);
  rig.arm.moving = false;
  rig.machine.on_arm_status(rig.arm, rig.now);
  rig.advance(2.9);
  rig.machine.on_arm_status(rig.arm, rig.now);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kNone);
  rig.advance(0.2);  // past judge_time (3 s)
  rig.machine.on_arm_status(rig.arm, rig.now);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kFailed);
  EXPECT_NE(rig.status().message.find("not seen"), std::string::npos);
}

// Abort from every situation sends STOP with the hand opening (even with a request in flight),
// ends in q0 idle, and marks a grasp in progress aborted.
TEST(GraspMachineTest, AbortFromEveryStateStopsAndOpens) {
  for (At at : kEverySituation) {
    SCOPED_TRACE(name(at));
    Rig rig;
    reach(rig, at);
    const GraspOutcome before = rig.status().outcome;
    const bool in_progress = rig.status().activity == GraspActivity::kGrasping;
    rig.command(GraspCommand::kAbort);
    const std::optional<ArmRequest> r = rig.take();
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->mode, Cmd::MODE_STOP);
    EXPECT_EQ(r->gripper, Cmd::GRIPPER_OPEN);
    EXPECT_EQ(rig.status().state, GraspState::kHandOpened);
    EXPECT_EQ(rig.status().activity, GraspActivity::kIdle);
    EXPECT_EQ(rig.status().last_action, GraspAction::kOpenHand);
    EXPECT_FALSE(rig.status().target.has_value());
    EXPECT_EQ(rig.status().outcome, in_progress ? GraspOutcome::kAborted : before);
    rig.executed(*r);
    rig.advance(0.8);
    rig.feed();
    EXPECT_FALSE(rig.take().has_value());  // idle: nothing more
  }
}

// A trajectory marked lost during the approach: the tool backs off straight up by `backoff`
// from where it is, with the same orientation, and the grasp ends in q0 with outcome failed.
TEST(GraspMachineTest, LostTrackDuringApproachBacksOff) {
  GraspSettings s;
  s.max_wait = 0;  // no wait for the track to return
  Rig rig(s);
  reach(rig, At::kQ0Tracking);
  const ArmRequest tracked = rig.run();
  rig.advance(0.8);
  rig.feed();
  rig.command(GraspCommand::kGrasp);
  rig.lose();
  EXPECT_EQ(rig.status().state, GraspState::kHandOpened);
  EXPECT_EQ(rig.status().activity, GraspActivity::kBackingOff);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kFailed);
  EXPECT_EQ(rig.status().message, "track lost");
  const std::optional<ArmRequest> r = rig.take();
  ASSERT_EQ(kind(r), Req::kMove);
  EXPECT_LT((r->position - (rig.arm.tool + Eigen::Vector3d(0, 0, 0.10))).norm(), 1e-12);
  const Eigen::Matrix3d before = pose_from_xyz_rpy(tracked.position, tracked.rpy).rotation();
  const Eigen::Matrix3d after = pose_from_xyz_rpy(r->position, r->rpy).rotation();
  EXPECT_LT((after - before).norm(), 1e-6);  // the tool keeps its orientation
  rig.advance(0.8);
  rig.executed(*r);
  EXPECT_EQ(rig.status().state, GraspState::kHandOpened);
  EXPECT_EQ(rig.status().activity, GraspActivity::kIdle);
  EXPECT_EQ(rig.status().outcome, GraspOutcome::kFailed);
  rig.feed();
  EXPECT_FALSE(rig.take().has_value());
}

// A track lost while waiting to close (the ball hidden longer than the predictor coasts): the arm
// holds (no request) and the machine waits; a fresh, sure track within max_wait sends the
// approach; one still lost at max_wait backs off, failed.
TEST(GraspMachineTest, LostTrackWhileWaitingWaitsUpToMaxWait) {
  GraspSettings s;
  s.max_wait = 3.0;
  for (const bool returns : {true, false}) {
    Rig rig(s);
    grasp_while_tracking(rig, 0.05);
    const std::optional<ArmRequest> wait = rig.take();
    ASSERT_EQ(kind(wait), Req::kMove) << rig.status().message;
    rig.advance(0.8);
    rig.executed(*wait);
    rig.lose();
    EXPECT_EQ(kind(rig.take()), Req::kNone);
    EXPECT_EQ(rig.status().state, GraspState::kApproaching);
    EXPECT_EQ(rig.status().message, "waiting to close: no fresh track of the object (2.2 s left)");
    rig.advance(1.5);
    rig.lose();
    EXPECT_EQ(kind(rig.take()), Req::kNone) << "still waiting at 2.3 s";
    EXPECT_EQ(rig.status().state, GraspState::kApproaching);
    rig.advance(1.0);  // 3.3 s after the command
    if (returns) {
      rig.feed_with_sigma(0.002);
      EXPECT_EQ(kind(rig.take()), Req::kApproach) << rig.status().message;
    } else {
      rig.lose();
      EXPECT_EQ(kind(rig.take()), Req::kMove) << "the back-off";
      EXPECT_EQ(rig.status().activity, GraspActivity::kBackingOff);
      EXPECT_EQ(rig.status().outcome, GraspOutcome::kFailed);
      EXPECT_EQ(rig.status().message, "track lost");
    }
  }
}

// No trajectory newer than max_trajectory_age during the approach also counts as a lost track.
TEST(GraspMachineTest, StaleTrackDuringApproachBacksOff) {
  GraspSettings s;
  s.max_wait = 0;
  Rig rig(s);
  reach(rig, At::kQ1);
  rig.advance(0.9);
  EXPECT_EQ(kind(rig.take()), Req::kApproach);  // still fresh: approaches
  Rig late(s);
  reach(late, At::kQ1);
  late.advance(1.1);
  const std::optional<ArmRequest> r = late.take();
  ASSERT_EQ(kind(r), Req::kMove);
  EXPECT_NEAR(r->position.z(), late.arm.tool.z() + 0.10, 1e-12);
  EXPECT_EQ(late.status().activity, GraspActivity::kBackingOff);
  EXPECT_EQ(late.status().outcome, GraspOutcome::kFailed);
}

// While tracking, a stale or lost trajectory gives no command, and tracking resumes when a
// fresh one arrives.
TEST(GraspMachineTest, NoCommandFromStaleOrLostTrajectory) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  rig.machine.on_trajectory(circle_path(rig.now - 1'100'000), rig.now - 1'150'000, rig.now);
  EXPECT_FALSE(rig.take().has_value());
  EXPECT_NE(rig.status().message.find("no fresh track"), std::string::npos);
  rig.lose();
  EXPECT_FALSE(rig.take().has_value());
  EXPECT_EQ(rig.status().activity, GraspActivity::kTracking);
  rig.advance(0.25);
  rig.feed();
  const std::optional<ArmRequest> r = rig.take();
  EXPECT_EQ(kind(r), Req::kMove);
  EXPECT_EQ(rig.status().message, "");
}

// A path below the table (plus margin) or outside the workspace gives no request and a message;
// the machine stays where it is.
TEST(GraspMachineTest, RefusesTargetsBelowTheTableOrOutsideTheWorkspace) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  rig.feed(-0.20);  // tool target at -0.10 m
  EXPECT_FALSE(rig.take().has_value());
  EXPECT_NE(rig.status().message.find("below the table"), std::string::npos)
      << rig.status().message;
  EXPECT_EQ(rig.status().activity, GraspActivity::kTracking);

  rig.machine.on_trajectory(still_path(rig.now, {1.5, 0, 0.10}), rig.now, rig.now);
  EXPECT_FALSE(rig.take().has_value());
  EXPECT_NE(rig.status().message.find("target refused"), std::string::npos);

  rig.feed(0.02);  // grasping a ball 2 cm above the table: the TCP would be below the margin
  rig.command(GraspCommand::kGrasp);
  ASSERT_EQ(rig.status().state, GraspState::kApproaching);
  EXPECT_FALSE(rig.take().has_value());
  EXPECT_EQ(rig.status().state, GraspState::kApproaching);
  EXPECT_NE(rig.status().message.find("below the table"), std::string::npos);
}

// Only one request is in flight: the next comes after the arm reports the previous executed or
// rejected, with sequence numbers one apart; abort alone is sent at once.
TEST(GraspMachineTest, AtMostOneRequestInFlight) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  const std::optional<ArmRequest> first = rig.take();
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->sequence, 100);
  for (int i = 0; i < 3; ++i) {
    rig.advance(0.25);
    rig.feed();
    EXPECT_FALSE(rig.take().has_value());
  }
  rig.arm.last_executed_sequence = 55;  // someone else's command
  rig.machine.on_arm_status(rig.arm, rig.now);
  EXPECT_FALSE(rig.take().has_value());
  rig.executed(*first);
  const std::optional<ArmRequest> second = rig.take();
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->sequence, 101);
  EXPECT_FALSE(rig.take().has_value());
  rig.command(GraspCommand::kAbort);
  const std::optional<ArmRequest> stop = rig.take();
  ASSERT_EQ(kind(stop), Req::kStop);
  EXPECT_EQ(stop->sequence, 102);
  EXPECT_FALSE(rig.take().has_value());
}

// A request the arm rejects frees the slot and is treated like a refusal: a message, and the
// machine tries again after the back-off (an approach goes back to q1).
TEST(GraspMachineTest, RejectedRequestIsARefusal) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  const std::optional<ArmRequest> r = rig.take();
  ASSERT_TRUE(r.has_value());
  rig.rejected(*r);
  EXPECT_NE(rig.status().message.find("rejected"), std::string::npos);
  EXPECT_EQ(rig.status().activity, GraspActivity::kTracking);
  rig.advance(GraspMachine::kRetryFirst);
  rig.feed();
  EXPECT_TRUE(rig.take().has_value());

  Rig approach;
  reach(approach, At::kQ2);
  const ArmRequest sent{approach.arm.last_received_sequence};  // the approach
  approach.rejected(sent);
  EXPECT_EQ(approach.status().state, GraspState::kApproaching);
  EXPECT_EQ(approach.status().last_action, GraspAction::kApproachObject);
  EXPECT_NE(approach.status().message.find("rejected the approach"), std::string::npos);
  approach.advance(GraspMachine::kRetryFirst);
  approach.feed();
  EXPECT_EQ(kind(approach.take()), Req::kApproach);
}

// A request with no answer for kAnswerTimeout (or 8 delays, if longer) is given up like a
// rejected one.
TEST(GraspMachineTest, UnansweredRequestTimesOut) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  ASSERT_TRUE(rig.take().has_value());
  const double limit = std::max(GraspMachine::kAnswerTimeout, 8 * rig.machine.delay_estimate());
  rig.advance(limit - 0.1);
  rig.feed();
  EXPECT_FALSE(rig.take().has_value());
  rig.advance(0.2);
  rig.feed();
  EXPECT_TRUE(rig.take().has_value());
}

// The delay estimate starts at default_delay and follows the measured interaction times, an
// interaction with N motion commands counting as N delays; other senders' interactions and a
// repeated value are not learnt.
TEST(GraspMachineTest, LearnsTheDelay) {
  Rig rig;
  EXPECT_DOUBLE_EQ(rig.machine.delay_estimate(), 0.78);
  rig.feed();
  rig.command(GraspCommand::kTrack);
  const std::optional<ArmRequest> move = rig.take();  // a tracking move: one command (MA)
  ASSERT_EQ(kind(move), Req::kMove) << rig.status().message;
  rig.executed(*move, false, 0.90);
  const double after_one = 0.7 * 0.78 + 0.3 * 0.90;
  EXPECT_NEAR(rig.machine.delay_estimate(), after_one, 1e-12);
  rig.machine.on_arm_status(rig.arm, rig.now);  // the same interaction again: not counted twice
  EXPECT_NEAR(rig.machine.delay_estimate(), after_one, 1e-12);
  rig.arm.last_executed_sequence = 55;  // another sender's interaction
  rig.arm.interaction_time = 3.0;
  rig.machine.on_arm_status(rig.arm, rig.now);
  EXPECT_NEAR(rig.machine.delay_estimate(), after_one, 1e-12);

  rig.advance(0.9);
  rig.feed();
  rig.command(GraspCommand::kGrasp);
  const std::optional<ArmRequest> approach = rig.take();  // MA + CLOSE: two delays
  ASSERT_EQ(kind(approach), Req::kApproach) << rig.status().message;
  // The executed status comes first, the interaction time with the next status (the driver).
  rig.executed(*approach, true);
  EXPECT_NEAR(rig.machine.delay_estimate(), after_one, 1e-12);
  rig.arm.interaction_time = 1.40;
  rig.machine.on_arm_status(rig.arm, rig.now);
  EXPECT_NEAR(rig.machine.delay_estimate(), 0.7 * after_one + 0.3 * 0.70, 1e-12);
}

// --no-prediction: the target is the last measured position (plus the stand-off); trajectories
// are ignored, and a measurement older than max_trajectory_age gives no command.
TEST(GraspMachineTest, NoPredictionAimsAtTheLastMeasurement) {
  GraspSettings settings;
  settings.use_prediction = false;
  Rig rig(settings);
  ASSERT_EQ(kind(rig.take()), Req::kNone);  // nothing unasked
  rig.feed();  // its points are ignored; it only says the track is alive
  rig.command(GraspCommand::kTrack);
  EXPECT_FALSE(rig.take().has_value());  // nothing measured yet
  const Eigen::Vector3d ball(0.50, 0.10, 0.12);
  rig.machine.on_measurement(ball, rig.now - 100'000);
  rig.machine.on_measurement(std::nullopt, rig.now - 50'000);  // not visible: keeps the last
  const std::optional<ArmRequest> r = rig.take();
  ASSERT_EQ(kind(r), Req::kMove) << rig.status().message;
  EXPECT_LT((r->position - (ball + Eigen::Vector3d(0, 0, 0.10))).norm(), 1e-9);
  EXPECT_EQ(r->source_utime, rig.now - 100'000);

  rig.advance(0.8);
  rig.executed(*r);
  rig.command(GraspCommand::kGrasp);
  const std::optional<ArmRequest> approach = rig.take();
  ASSERT_EQ(kind(approach), Req::kApproach) << rig.status().message;
  EXPECT_LT((approach->position - ball).norm(), 1e-9);

  Rig stale(settings);
  ASSERT_EQ(kind(stale.take()), Req::kNone);
  stale.command(GraspCommand::kTrack);
  stale.machine.on_measurement(ball, stale.now - 1'100'000);
  EXPECT_FALSE(stale.take().has_value());
  // Through an occlusion the predictor still tracks (fresh trajectories): the baseline aims at
  // where the ball was last seen, however old; a lost track stops it.
  stale.feed();
  const std::optional<ArmRequest> occluded = stale.take();
  ASSERT_EQ(kind(occluded), Req::kMove) << stale.status().message;
  EXPECT_LT((occluded->position - (ball + Eigen::Vector3d(0, 0, 0.10))).norm(), 1e-9);
  stale.advance(0.8);
  stale.executed(*occluded);
  stale.lose();
  EXPECT_FALSE(stale.take().has_value());
}

// Each command's reply: accepted, or refused by the state (the table's "refused" and "ignored")
// or by a bad stand-off, with the reason that status().message shows.
TEST(GraspMachineTest, CommandRepliesSayAcceptedOrWhyRefused) {
  struct Row {
    At at;
    GraspCommand command;
    double standoff;
    CommandResult result;
  };
  const std::vector<Row> rows = {
      {At::kQ0Idle, GraspCommand::kTrack, 0, CommandResult::kAccepted},
      {At::kQ0Idle, GraspCommand::kTrack, -0.1, CommandResult::kRefusedBadArgument},
      {At::kQ0Idle, GraspCommand::kGrasp, 0, CommandResult::kAccepted},
      {At::kQ0Idle, GraspCommand::kRelease, 0, CommandResult::kRefusedState},
      {At::kQ0Homing, GraspCommand::kHome, 0, CommandResult::kAccepted},
      {At::kQ0BackingOff, GraspCommand::kTrack, 0, CommandResult::kRefusedState},
      {At::kQ1, GraspCommand::kHome, 0, CommandResult::kRefusedState},
      {At::kQ2, GraspCommand::kGrasp, 0, CommandResult::kRefusedState},
      {At::kQ2, GraspCommand::kAbort, 0, CommandResult::kAccepted},
      {At::kQ4Idle, GraspCommand::kTrack, 0, CommandResult::kRefusedState},
      {At::kQ4Idle, GraspCommand::kRelease, 0, CommandResult::kAccepted},
  };
  for (const Row& row : rows) {
    SCOPED_TRACE(std::string(name(row.at)) + " + " + to_string(row.command));
    Rig rig;
    reach(rig, row.at);
    rig.advance(0.1);
    rig.feed();
    const CommandReply reply = rig.machine.on_command(row.command, row.standoff, rig.now);
    EXPECT_EQ(reply.result, row.result) << to_string(reply.result) << ": " << reply.reason;
    if (row.result == CommandResult::kAccepted) {
      EXPECT_EQ(reply.reason, "");
    } else {
      EXPECT_FALSE(reply.reason.empty());
      EXPECT_EQ(reply.reason, rig.status().message);
    }
  }
  Rig stale;  // a grasp without a fresh track
  reach(stale, At::kQ0Idle);
  stale.advance(2.0);
  const CommandReply reply = stale.machine.on_command(GraspCommand::kGrasp, 0, stale.now);
  EXPECT_EQ(reply.result, CommandResult::kRefusedState);
  EXPECT_EQ(reply.reason, "grasp refused: no fresh track of the object");
  EXPECT_EQ(stale.machine.on_command(static_cast<GraspCommand>(9), 0, stale.now).result,
            CommandResult::kRefusedUnknownCommand);
}

// Abort, then home, before the STOP goes out (the arm not connected): the STOP has precedence,
// the HOME follows it once the STOP is executed.
TEST(GraspMachineTest, StopGoesBeforeAHomeAskedForAfterIt) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  rig.arm.connected = false;
  rig.machine.on_arm_status(rig.arm, rig.now);
  rig.command(GraspCommand::kAbort);
  rig.command(GraspCommand::kHome);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kStop);
  EXPECT_EQ(rig.status().activity, GraspActivity::kHoming);
  EXPECT_FALSE(rig.take().has_value());  // not connected
  rig.arm.connected = true;
  rig.machine.on_arm_status(rig.arm, rig.now);
  const std::optional<ArmRequest> stop = rig.take();
  EXPECT_EQ(kind(stop), Req::kStop);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kHome);
  EXPECT_FALSE(rig.take().has_value());  // the STOP in flight
  rig.executed(*stop);
  EXPECT_EQ(kind(rig.take()), Req::kHome);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kNone);
}

// Release, then home: a0 first, then HOME; and when the arm rejects the a0, a0 is sent again
// before the HOME (a0 hides the HOME, which the activity takes up again).
TEST(GraspMachineTest, OpenGoesBeforeAHomeAndIsRetriedFirst) {
  Rig rig;
  reach(rig, At::kQ4Idle);
  rig.command(GraspCommand::kRelease);
  const std::optional<ArmRequest> open = rig.take();
  ASSERT_EQ(kind(open), Req::kOpen);
  EXPECT_EQ(rig.status().state, GraspState::kHandOpened);
  rig.command(GraspCommand::kHome);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kHome);
  rig.rejected(*open);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kOpen);
  rig.advance(GraspMachine::kRetryFirst);  // the back-off
  const std::optional<ArmRequest> again = rig.take();
  ASSERT_EQ(kind(again), Req::kOpen);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kHome);
  rig.executed(*again);
  EXPECT_EQ(kind(rig.take()), Req::kHome);
  EXPECT_EQ(rig.status().activity, GraspActivity::kHoming);
}

// A grasp asked for in q0 while the gripper is not reported OPEN (unknown after a start): a0
// first, the state stays q1, and the approach follows (a0 in q1 does not undo the grasp).
TEST(GraspMachineTest, GraspWithTheHandNotReportedOpenOpensFirst) {
  Rig rig({}, Status::GRIPPER_UNKNOWN);
  rig.feed();
  EXPECT_EQ(rig.machine.next_action(), NextAction::kNone);
  rig.command(GraspCommand::kGrasp);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kOpen);
  EXPECT_EQ(rig.status().state, GraspState::kApproaching);
  const std::optional<ArmRequest> open = rig.take();
  ASSERT_EQ(kind(open), Req::kOpen);
  EXPECT_EQ(rig.status().state, GraspState::kApproaching);
  EXPECT_EQ(rig.status().activity, GraspActivity::kGrasping);
  rig.executed(*open);
  EXPECT_EQ(kind(rig.take()), Req::kApproach) << rig.status().message;
  EXPECT_EQ(rig.status().state, GraspState::kGrasping);
}

// A back-off that the lost track calls for while a0 is pending goes out after the a0.
TEST(GraspMachineTest, OpenGoesBeforeABackoff) {
  GraspSettings s;
  s.max_wait = 0;  // the back-off at once
  Rig rig(s, Status::GRIPPER_UNKNOWN);
  rig.feed();
  rig.command(GraspCommand::kGrasp);
  rig.lose();
  EXPECT_EQ(rig.status().activity, GraspActivity::kBackingOff);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kOpen);
  const std::optional<ArmRequest> open = rig.take();
  ASSERT_EQ(kind(open), Req::kOpen);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kBackoff);
  rig.executed(*open);
  const std::optional<ArmRequest> up = rig.take();
  ASSERT_EQ(kind(up), Req::kMove) << rig.status().message;
  Eigen::Vector3d expected = rig.arm.tool + Eigen::Vector3d(0, 0, 0.10);
  expected.z() = std::min(expected.z(), rig.geometry.workspace.max.z());
  EXPECT_LT((up->position - expected).norm(), 1e-12);
}

// Abort hides every other pending request: after the STOP, no lift, a0 or back-off follows.
TEST(GraspMachineTest, AbortHidesTheLift) {
  Rig rig;
  reach(rig, At::kQ3Grasping);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kLift);
  rig.command(GraspCommand::kAbort);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kStop);
  const std::optional<ArmRequest> stop = rig.take();
  ASSERT_EQ(kind(stop), Req::kStop);
  EXPECT_EQ(rig.machine.next_action(), NextAction::kNone);
  rig.executed(*stop);
  EXPECT_FALSE(rig.take().has_value());
}

// A request that ARM_STATUS does not show received (the driver never got it) is sent again with
// the same sequence and content 0.5 s after it was sent and 0.5 s after each resend; once the
// status shows it received, never again.
TEST(GraspMachineTest, ResendsALostRequestUnderTheSameSequence) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  const std::optional<ArmRequest> first = rig.machine.take_request(rig.now);  // lost on the way
  ASSERT_EQ(kind(first), Req::kMove) << rig.status().message;
  const int64_t sent = rig.now;
  for (int64_t after : {100'000, 300'000, 499'999}) {
    rig.now = sent + after;
    rig.feed();
    rig.publish();
    EXPECT_FALSE(rig.machine.take_request(rig.now).has_value()) << after;
  }
  rig.now = sent + 500'000;
  rig.publish();
  const std::optional<ArmRequest> again = rig.machine.take_request(rig.now);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->sequence, first->sequence);
  EXPECT_EQ(again->mode, first->mode);
  EXPECT_TRUE(again->position == first->position);
  EXPECT_TRUE(again->rpy == first->rpy);
  EXPECT_EQ(again->target_utime, first->target_utime);
  EXPECT_EQ(again->source_utime, first->source_utime);
  EXPECT_EQ(rig.machine.resends(), 1u);
  rig.now = sent + 999'999;
  rig.publish();
  EXPECT_FALSE(rig.machine.take_request(rig.now).has_value());
  rig.now = sent + 1'000'000;
  rig.publish();
  ASSERT_TRUE(rig.machine.take_request(rig.now).has_value());
  EXPECT_EQ(rig.machine.resends(), 2u);
  rig.arm.last_received_sequence = first->sequence;  // it arrived: the driver has it
  for (int i = 1; i <= 10; ++i) {
    rig.now = sent + 1'000'000 + i * 100'000;
    rig.publish();
    EXPECT_FALSE(rig.machine.take_request(rig.now).has_value());
  }
  EXPECT_EQ(rig.machine.resends(), 2u);
}

// A driver restart (driver_start_utime changes) with a request in flight: not resent (the old
// driver may have executed it); abandoned as failed, "driver restarted", and the next request is
// computed afresh at once under a new sequence.
TEST(GraspMachineTest, NoResendAcrossADriverRestart) {
  Rig rig;
  rig.arm.driver_start_utime = kT0 - 3600 * kSecond;
  rig.publish();
  reach(rig, At::kQ0Tracking);
  const std::optional<ArmRequest> first = rig.machine.take_request(rig.now);
  ASSERT_EQ(kind(first), Req::kMove) << rig.status().message;
  rig.advance(0.3);
  rig.arm.driver_start_utime = rig.now - 200'000;  // a new driver process
  rig.arm.last_received_sequence = -1;
  rig.feed();
  rig.publish();
  EXPECT_EQ(rig.status().message, "driver restarted: abandoned the tracking target (request " +
                                      std::to_string(first->sequence) + ")");
  const std::optional<ArmRequest> fresh = rig.machine.take_request(rig.now);
  ASSERT_EQ(kind(fresh), Req::kMove) << rig.status().message;
  EXPECT_EQ(fresh->sequence, first->sequence + 1);
  EXPECT_EQ(rig.machine.resends(), 0u);
  EXPECT_EQ(rig.machine.consecutive_rejections(), 0);
}

// A new watchdog stop on ARM_STATUS with a request in flight (the driver's STOP replaced it):
// the request is abandoned and, the track fresh, the next one computed at once; the same
// watchdog text again changes nothing.
TEST(GraspMachineTest, WatchdogStopAbandonsTheRequestInFlight) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  const std::optional<ArmRequest> first = rig.take();
  ASSERT_EQ(kind(first), Req::kMove) << rig.status().message;
  rig.advance(0.3);
  rig.arm.watchdog = "stopped: 'sg-grasp@lab1:412' silent for 1.62 s";
  rig.feed();
  rig.publish();
  EXPECT_EQ(rig.status().message,
            "the driver's watchdog stopped the arm: abandoned the tracking target (request " +
                std::to_string(first->sequence) + ")");
  const std::optional<ArmRequest> next = rig.take();
  ASSERT_EQ(kind(next), Req::kMove);
  EXPECT_EQ(next->sequence, first->sequence + 1);
  rig.advance(0.3);
  rig.publish();  // the same watchdog text: nothing abandoned
  EXPECT_FALSE(rig.take().has_value());
}

// No ARM_STATUS for more than arm_status_timeout (1 s): no request and no heartbeat (arm_need
// silent), the silence reported; when statuses return, requests resume. An abort's STOP goes
// out regardless.
TEST(GraspMachineTest, SilentArmStatusStopsRequestsAndHeartbeats) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  const ArmRequest first = rig.run();
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kWanted);
  rig.advance(1.0);
  rig.feed();
  EXPECT_FALSE(rig.machine.arm_status_silence(rig.now).has_value());  // 1.0 s: not yet
  rig.advance(0.3);
  rig.feed();
  EXPECT_FALSE(rig.machine.take_request(rig.now).has_value());
  ASSERT_TRUE(rig.machine.arm_status_silence(rig.now).has_value());
  EXPECT_NEAR(*rig.machine.arm_status_silence(rig.now), 1.3, 1e-9);
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kSilent);
  rig.publish();  // statuses return
  EXPECT_FALSE(rig.machine.arm_status_silence(rig.now).has_value());
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kWanted);
  const std::optional<ArmRequest> next = rig.machine.take_request(rig.now);
  ASSERT_EQ(kind(next), Req::kMove);
  EXPECT_EQ(next->sequence, first.sequence + 1);
  rig.advance(1.5);
  rig.command(GraspCommand::kAbort);
  EXPECT_EQ(kind(rig.machine.take_request(rig.now)), Req::kStop);
}

// After the k-th consecutive rejection the next request waits min(0.25 s * 2^(k-1), 4 s):
// 0.25, 0.5, 1, 2, 4 and 4 s; an executed request resets the count.
TEST(GraspMachineTest, RejectionsAreBackedOff) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  std::optional<ArmRequest> r = rig.take();
  ASSERT_TRUE(r.has_value());
  int k = 0;
  for (double wait : {0.25, 0.5, 1.0, 2.0, 4.0, 4.0}) {
    SCOPED_TRACE(wait);
    rig.rejected(*r);
    EXPECT_EQ(rig.machine.consecutive_rejections(), ++k);
    const int64_t at = rig.now;
    rig.now = at + std::llround(wait * kSecond) - 1000;
    rig.feed();
    EXPECT_FALSE(rig.take().has_value());
    rig.now = at + std::llround(wait * kSecond);
    rig.feed();
    r = rig.take();
    ASSERT_EQ(kind(r), Req::kMove) << rig.status().message;
  }
  rig.executed(*r);
  EXPECT_EQ(rig.machine.consecutive_rejections(), 0);
  rig.feed();
  r = rig.take();
  ASSERT_TRUE(r.has_value());
  rig.rejected(*r);
  EXPECT_EQ(rig.machine.retry_utime(), rig.now + 250'000);
}

// A rejection because another sender holds the commander lease shows as "waiting: arm
// commanded by '<holder>'" through the retries, and goes when a request is executed; an
// operator's abort waits for no back-off.
TEST(GraspMachineTest, LeaseRejectionSaysWhoCommandsTheArm) {
  Rig rig;
  reach(rig, At::kQ0Tracking);
  std::optional<ArmRequest> r = rig.take();
  ASSERT_TRUE(r.has_value());
  rig.arm.rejection_reason = "arm commanded by 'sg-arm-ctl@bench:77'";
  rig.rejected(*r);
  const std::string waiting = "waiting: arm commanded by 'sg-arm-ctl@bench:77'";
  EXPECT_EQ(rig.status().message.substr(0, waiting.size()), waiting) << rig.status().message;
  rig.advance(0.25);
  rig.feed();
  r = rig.take();
  ASSERT_EQ(kind(r), Req::kMove);
  EXPECT_EQ(rig.status().message.substr(0, waiting.size()), waiting) << rig.status().message;
  rig.rejected(*r);  // the second: 0.5 s
  rig.advance(0.1);
  rig.command(GraspCommand::kAbort);
  EXPECT_EQ(kind(rig.take()), Req::kStop);  // at once
  rig.arm.rejection_reason = "";
  rig.executed(ArmRequest{rig.arm.last_received_sequence});
  EXPECT_EQ(rig.status().message, "");
}

// The commander lease: not wanted before a command; wanted while tracking a fresh track; silent
// (no heartbeat, with the message) when that track goes stale, wanted again when it returns;
// after an abort wanted while the STOP is in flight and the arm still moves from it, then none.
TEST(GraspMachineTest, ArmNeedFollowsTheTrackAndTheArm) {
  Rig rig;
  rig.feed();
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kNone);
  rig.command(GraspCommand::kTrack);
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kWanted);
  const ArmRequest move = rig.run(true);
  rig.advance(1.1);  // the trajectory is older than max_trajectory_age
  rig.publish();
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kSilent);
  EXPECT_EQ(rig.status().message,
            "no fresh track of the object: heartbeats stopped (the driver's watchdog stops the "
            "arm)");
  rig.feed();
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kWanted);
  EXPECT_EQ(rig.status().message, "");
  rig.command(GraspCommand::kAbort);
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kWanted);  // the STOP planned
  const std::optional<ArmRequest> stop = rig.take();
  ASSERT_EQ(kind(stop), Req::kStop);
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kWanted);  // in flight
  rig.executed(*stop, true);
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kWanted);  // its own command still moving
  rig.arm.moving = false;
  rig.publish();
  EXPECT_EQ(rig.machine.arm_need(rig.now), ArmNeed::kNone);
  EXPECT_GT(stop->sequence, move.sequence);
}

// The names shown on GRASP_STATUS and in logs.
TEST(GraspMachineTest, Names) {
  EXPECT_STREQ(to_string(GraspState::kHandOpened), "q0 hand opened");
  EXPECT_STREQ(to_string(GraspState::kObjectLifted), "q4 object lifted");
  EXPECT_STREQ(to_string(GraspActivity::kTracking), "tracking");
  EXPECT_STREQ(to_string(GraspActivity::kBackingOff), "backing off");
  EXPECT_STREQ(to_string(GraspAction::kCloseHand), "a2 close hand");
  EXPECT_STREQ(to_string(GraspAction::kNone), "none");
  EXPECT_STREQ(to_string(GraspOutcome::kSuccess), "success");
  EXPECT_STREQ(to_string(GraspCommand::kAbort), "abort");
  EXPECT_STREQ(to_string(CommandResult::kAccepted), "accepted");
  EXPECT_STREQ(to_string(CommandResult::kRefusedState), "refused: state");
  EXPECT_STREQ(to_string(static_cast<CommandResult>(42)), "unknown");
}

}  // namespace
}  // namespace sg::grasp
