// The plausibility gate on OBJECT_TRAJECTORY in sg-grasp (check_trajectory and GraspNode): points
// that are not finite or far outside the workspace, a period that is zero, negative or absurd,
// more points than the horizon bound, times far from now; each refused with its reason, counted,
// reported on GRASP_STATUS at most once a second, and never turned into an arm target.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "common/config.hpp"
#include "grasp/grasp_messages.hpp"
#include "grasp/grasp_node.hpp"
#include "grasp/grasp_settings.hpp"
#include "predictor/predictor_settings.hpp"
#include "predictor/trajectory_predictor.hpp"

namespace sg::grasp {
namespace {

using stereograsp::trajectory_t;

constexpr int64_t kSecond = 1'000'000;
constexpr int64_t kT0 = 1'790'000'000 * kSecond;

/// A trajectory made at `now`: the ball held still at (0.45, 0, 0.10), 16 points at 4 Hz.
trajectory_t good(int64_t now) {
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

/// The reason check_trajectory() gives `m` at kT0 with the A465's workspace and the defaults.
std::optional<TrajectoryRefusal> refusal(const trajectory_t& m, int64_t now = kT0) {
  const TrajectoryCheck c = check_trajectory(m, ArmGeometry::a465().workspace, InputGate{}, now);
  if (c.path) return std::nullopt;
  EXPECT_FALSE(c.why.empty());
  return c.reason;
}

/// `good(kT0)` changed by `change`.
template <class Change>
trajectory_t bad(Change change) {
  trajectory_t m = good(kT0);
  change(m);
  return m;
}

// A well-formed trajectory on the ball passes; a point inside the 0.25 m margin passes.
TEST(CheckTrajectory, AcceptsAPlausibleTrajectory) {
  EXPECT_EQ(refusal(good(kT0)), std::nullopt);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) {
              m.position[3] = {1.14, -1.14, -0.19};
            })),
            std::nullopt);
  EXPECT_EQ(refusal(good(kT0 - 4 * kSecond)), std::nullopt);  // 4 s old: within 5 s
}

// Each implausible field gives its reason.
TEST(CheckTrajectory, RefusesEachImplausibleField) {
  using R = TrajectoryRefusal;
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(refusal(bad([&](trajectory_t& m) { m.position[5][1] = nan; })), R::kNonFinite);
  EXPECT_EQ(refusal(bad([&](trajectory_t& m) { m.position[0][2] = -inf; })), R::kNonFinite);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) {
              m.position[15] = {1e300, 1e300, 1e300};
            })),
            R::kOutsideWorkspace);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) {
              m.position[2] = {0.45, 0, -0.5};
            })),
            R::kOutsideWorkspace);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) { m.period_us = 0; })), R::kBadPeriod);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) { m.period_us = -250'000; })), R::kBadPeriod);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) { m.period_us = int64_t{1} << 62; })), R::kBadPeriod);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) {
              m.num_points = kMaxTrajectoryPoints + 1;
              m.position.assign(static_cast<size_t>(m.num_points), {0.45, 0, 0.1});
              m.position_sigma.assign(static_cast<size_t>(m.num_points), {0.001, 0.001, 0.001});
            })),
            R::kTooManyPoints);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) { m.num_points = 17; })), R::kMalformed);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) { m.start_utime += 10 * kSecond; })),
            R::kTimeFarFromNow);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) { m.utime -= 10 * kSecond; })), R::kTimeFarFromNow);
  EXPECT_EQ(refusal(bad([](trajectory_t& m) {
              m.utime = m.start_utime = std::numeric_limits<int64_t>::max();
            })),
            R::kTimeFarFromNow);
}

// A lost track may carry NaNs and no points; its times and period are still checked.
TEST(CheckTrajectory, ALostTrackIsCheckedForTimesOnly) {
  trajectory_t lost = good(kT0);
  lost.status = trajectory_t::STATUS_LOST;
  lost.position.assign(16, std::vector<double>{std::nan(""), 0, 0});
  lost.position_sigma.assign(16, std::vector<double>{0.001, 0.001, 0.001});
  EXPECT_EQ(refusal(lost), std::nullopt);
  lost.start_utime = kT0 + 3600 * kSecond;
  EXPECT_EQ(refusal(lost), TrajectoryRefusal::kTimeFarFromNow);
}

// max_time_offset 0 turns the time check off (replays), not the absurd-time check.
TEST(CheckTrajectory, ZeroOffsetTurnsTheTimeCheckOff) {
  InputGate gate;
  gate.max_time_offset = 0;
  const auto workspace = ArmGeometry::a465().workspace;
  EXPECT_TRUE(check_trajectory(good(kT0 - 3600 * kSecond), workspace, gate, kT0).path);
  trajectory_t forged = good(kT0);
  forged.start_utime = std::numeric_limits<int64_t>::max();
  EXPECT_EQ(check_trajectory(forged, workspace, gate, kT0).reason,
            TrajectoryRefusal::kTimeFarFromNow);
}

// The bounds are sg-predictor's own: its largest horizon and its period range.
TEST(CheckTrajectory, BoundsMatchThePredictors) {
  EXPECT_EQ(kMaxTrajectoryPoints, predictor::kMaxHorizon);
  for (const KeyInfo& k :
       declared_keys([](const Config& c) { predictor::read_predictor_settings(c); })) {
    if (k.key == "predictor.horizon") {
      EXPECT_EQ(k.range.max, kMaxTrajectoryPoints);
    }
    if (k.key == "predictor.period") {
      EXPECT_DOUBLE_EQ(k.range.min * 1e6, static_cast<double>(kMinPeriodUs));
      EXPECT_DOUBLE_EQ(k.range.max * 1e6, static_cast<double>(kMaxPeriodUs));
    }
  }
}

/// A node whose arm is at the ready pose and connected.
struct Rig {
  Rig() : node(ArmGeometry::a465(), GraspSettings{}, 100, 0.25) {
    arm.state = stereograsp::arm_status_t::STATE_IDLE;
    const double ready[6] = {0, 0, std::numbers::pi / 2, 0, std::numbers::pi / 2, 0};
    for (int i = 0; i < 6; ++i) arm.joints[i] = ready[i];
    const Eigen::Vector3d tool =
        arm::forward_kinematics(ArmGeometry::a465(), Eigen::Map<const Joints>(ready)).translation();
    for (int i = 0; i < 3; ++i) arm.tool_position[i] = tool[i];
    arm.last_executed_sequence = arm.last_rejected_sequence = -1;
    node.on_arm_status(arm, now);
  }
  /// Polls 10 ms on; a command is executed at once, and ARM_STATUS comes every step (as the
  /// driver's does, at 10 Hz or more: a silent one stops sg-grasp's requests). Returns the
  /// command sent, if any.
  std::optional<stereograsp::arm_cmd_t> step() {
    now += 10'000;
    const GraspNode::Output out = node.poll(now);
    if (out.arm_command) arm.last_executed_sequence = out.arm_command->sequence;
    node.on_arm_status(arm, now);
    return out.arm_command;
  }
  const CommandRecord& track() {
    stereograsp::grasp_command_t c{};
    c.utime = now;
    c.sequence = ++sequence;
    c.command = stereograsp::grasp_command_t::COMMAND_TRACK;
    c.sender = "test";
    return node.on_command(c, now);
  }
  GraspNode node;
  stereograsp::arm_status_t arm{};
  int64_t now = kT0;
  int64_t sequence = 0;
};

// Forged trajectories (1e300 points, a future start) are refused and counted, never become an arm
// target, and do not stop a good trajectory afterwards from being followed.
TEST(GraspNodeGate, ImplausibleTrajectoriesNeverBecomeTargets) {
  Rig rig;
  trajectory_t far = good(rig.now);
  far.position.assign(16, {1e300, 1e300, 1e300});
  trajectory_t future = good(rig.now + 3600 * kSecond);
  for (int i = 0; i < 10; ++i) {
    EXPECT_NE(rig.node.on_trajectory(far, rig.now), "");
    EXPECT_NE(rig.node.on_trajectory(future, rig.now), "");
  }
  EXPECT_EQ(rig.node.refused_trajectories(TrajectoryRefusal::kOutsideWorkspace), 10u);
  EXPECT_EQ(rig.node.refused_trajectories(TrajectoryRefusal::kTimeFarFromNow), 10u);
  rig.track();
  for (int i = 0; i < 100; ++i) {  // only the first a0 (open hand): no motion to a target
    if (const auto c = rig.step()) {
      EXPECT_NE(c->mode, stereograsp::arm_cmd_t::MODE_CARTESIAN);
    }
    rig.node.on_trajectory(far, rig.now);
  }
  const trajectory_t fine = good(rig.now);
  EXPECT_EQ(rig.node.on_trajectory(fine, rig.now), "");
  std::optional<stereograsp::arm_cmd_t> target;
  for (int i = 0; i < 10 && !target; ++i) target = rig.step();
  ASSERT_TRUE(target.has_value());
  EXPECT_EQ(target->mode, stereograsp::arm_cmd_t::MODE_CARTESIAN);
  EXPECT_NEAR(target->position[0], 0.45, 0.05);
  EXPECT_EQ(target->utime, fine.utime);  // dated by the good trajectory, not a refused one
}

// The refusals ride on GRASP_STATUS's message with their counts by reason, and a flood of them
// (100 a poll for 3 s) changes the message at most once a second: GRASP_STATUS stays near its
// period (4 Hz) instead of following the flood.
TEST(GraspNodeGate, RefusalsAreReportedOnGraspStatusRateLimited) {
  Rig rig;
  trajectory_t nan_point = good(rig.now);
  nan_point.position[7][0] = std::nan("");
  int statuses = 0;
  std::string last;
  for (int i = 0; i < 300; ++i, rig.now += 10'000) {
    trajectory_t bad_period = good(rig.now);
    bad_period.period_us = 0;
    for (int n = 0; n < 50; ++n) {
      rig.node.on_trajectory(nan_point, rig.now);
      rig.node.on_trajectory(bad_period, rig.now);
    }
    if (const auto out = rig.node.poll(rig.now); out.status) {
      ++statuses;
      last = out.status->message;
    }
  }
  EXPECT_LE(statuses, 3 * 4 + 3 + 2);  // the period, the note's changes, the first
  EXPECT_NE(last.find("OBJECT_TRAJECTORY refused "), std::string::npos) << last;
  EXPECT_NE(last.find("non-finite "), std::string::npos) << last;
  EXPECT_NE(last.find("bad period "), std::string::npos) << last;
  EXPECT_NE(last.find("; last: "), std::string::npos) << last;
  EXPECT_EQ(rig.node.refused_trajectories(TrajectoryRefusal::kNonFinite), 15000u);
  EXPECT_EQ(rig.node.refused_trajectories(TrajectoryRefusal::kBadPeriod), 15000u);
  EXPECT_EQ(rig.node.refusal_note().rfind("OBJECT_TRAJECTORY refused 30000 (non-finite 15000, "
                                          "bad period 15000); last: ",
                                          0),
            0u)
      << rig.node.refusal_note();
}

// Configured through the grasp section: the margin and the time offset, range-checked.
TEST(GraspNodeGate, TheGateIsConfigured) {
  const GraspSettings s = read_grasp_settings(
      Config::parse("grasp:\n  position_margin: 0.1\n  max_time_offset: 2.5\n"));
  EXPECT_DOUBLE_EQ(s.input_gate.margin, 0.1);
  EXPECT_DOUBLE_EQ(s.input_gate.max_time_offset, 2.5);
  EXPECT_THROW(read_grasp_settings(Config::parse("grasp:\n  position_margin: -0.1\n")),
               ConfigError);
  EXPECT_THROW(read_grasp_settings(Config::parse("grasp:\n  max_time_offset: .nan\n")),
               ConfigError);
}

}  // namespace
}  // namespace sg::grasp
