#pragma once

/// The grasp machine's values as LCM messages and back: the one place sg-grasp and the in-process
/// trials (system/grasp_trial.hpp) convert, so both speak to the arm alike.
///
///     machine.on_arm_status(arm_view_of(arm_status), now);
///     if (auto path = path_from(trajectory, &why)) machine.on_trajectory(*path, ...);
///     bus.publish("ARM_COMMAND", to_arm_cmd(*machine.take_request(now), trajectory.utime));
///     bus.publish("GRASP_STATUS", to_grasp_status(machine.status(), now, last_command));

#include <optional>
#include <string>

#include "grasp/grasp_machine.hpp"
#include "grasp/interception.hpp"
#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/arm_status_t.hpp"
#include "stereograsp/grasp_status_t.hpp"
#include "stereograsp/trajectory_t.hpp"

namespace sg::grasp {

/// An ArmRequest as the ARM_COMMAND it stands for; `utime` is the message time of the decision.
stereograsp::arm_cmd_t to_arm_cmd(const ArmRequest& request, int64_t utime,
                                  const std::string& sender = "sg-grasp");

/// What the machine needs of an ARM_STATUS.
ArmView arm_view_of(const stereograsp::arm_status_t& status);

/// The answer to the last GRASP_COMMAND: its sequence (-1 before any) and the reply.
struct CommandRecord {
  int64_t sequence = -1;
  CommandReply reply;
};

/// The machine's status as GRASP_STATUS (a missing target is NaN), with the answer to the last
/// command (command_sequence, command_result, command_reason).
stereograsp::grasp_status_t to_grasp_status(const GraspStatusView& view, int64_t utime,
                                            const CommandRecord& command = {});

/// An OBJECT_TRAJECTORY as a path; nullopt, with the reason in `why`, when it is malformed (a
/// period that is not positive, num_points that disagrees with the points, a point that is not
/// three finite numbers in a track that is not lost).
std::optional<PredictedPath> path_from(const stereograsp::trajectory_t& trajectory,
                                       std::string* why = nullptr);

/// Why sg-grasp refused an OBJECT_TRAJECTORY.
enum class TrajectoryRefusal {
  kMalformed,         ///< num_points disagrees with the points
  kNonFinite,         ///< a point that is not three finite numbers (in a track not lost)
  kOutsideWorkspace,  ///< a point outside the arm's workspace widened by InputGate::margin
  kBadPeriod,         ///< period_us not in [kMinPeriodUs, kMaxPeriodUs]
  kTooManyPoints,     ///< num_points above kMaxTrajectoryPoints
  kTimeFarFromNow,    ///< utime or start_utime too far from the receiver's clock, or absurd
};
constexpr int kTrajectoryRefusals = 6;
/// "malformed", "non-finite", "outside the workspace", "bad period", "too many points", "time far
/// from now".
const char* to_string(TrajectoryRefusal reason);

/// Bounds of a plausible trajectory: sg-predictor's own (predictor_settings: a period of 1 ms to
/// 60 s, a horizon of at most predictor::kMaxHorizon = 1000 points; tests/grasp tie them).
constexpr int64_t kMinPeriodUs = 1'000;
constexpr int64_t kMaxPeriodUs = 60'000'000;
constexpr int kMaxTrajectoryPoints = 1000;
/// Times after this (2100-01-01) are absurd whatever the gate says (and keep t + n * period far
/// from overflowing).
constexpr int64_t kLatestUtime = 4'102'444'800'000'000;

/// An OBJECT_TRAJECTORY checked for what moves the arm (docs/grasping.md, "Plausibility gates"):
/// path_from()'s checks, then period_us, num_points, utime and start_utime within
/// gate.max_time_offset of `now` (and positive, before kLatestUtime), and, for a track that is
/// not lost, every point inside `workspace` widened by gate.margin.
struct TrajectoryCheck {
  std::optional<PredictedPath> path;  ///< the path when accepted
  TrajectoryRefusal reason = TrajectoryRefusal::kMalformed;  ///< when refused
  std::string why;                                            ///< when refused: one line
};
TrajectoryCheck check_trajectory(const stereograsp::trajectory_t& trajectory,
                                 const arm::Workspace& workspace, const InputGate& gate,
                                 int64_t now);

}  // namespace sg::grasp
