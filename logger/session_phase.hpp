#pragma once

/// Which part of a session a moment of its log belongs to: the robot-guided calibration (the arm
/// carrying the ball before any grasp machine runs), the grasp machine idle, tracking the ball,
/// approaching it, or the ball carried in the hand. sg-report scores the predictions per phase
/// (logger/session_stats.hpp) and leaves the calibration and the carried ball out of figure 5.
///
///     sg::logger::SessionPhase phases;
///     phases.advance(recv);                           // every event, in log order, first
///     phases.on_grasp_status(recv, state, activity);  // GRASP_STATUS
///     phases.on_sim_arm_state(recv, holding);         // SIM_ARM_STATE (a simulated session)
///     phases.on_arm_command(recv);                    // ARM_COMMAND
///     sg::logger::Phase now = phases.current();
///     std::optional<sg::logger::Phase> then = phases.at(earlier_recv);
///
/// The rule (docs/logs.md, "Phases"), from GRASP_STATUS alone, SIM_ARM_STATE only where present:
///
///  - before the first GRASP_STATUS: **calibration** while the hand holds the ball
///    (SIM_ARM_STATE.holding_object) or, without a fresh SIM_ARM_STATE, once the arm has been
///    commanded (an ARM_COMMAND with no grasp machine running is the robot-guided calibration);
///    otherwise **no grasp machine** (a session of the cameras and the predictor alone);
///  - with the grasp machine: **carried** while the hand holds the ball: SIM_ARM_STATE says so
///    where it is fresh, else the machine is in q3 hand closed or q4 object lifted;
///    **approach** in q2 grasping (from the approach command, which carries the CLOSE, until the
///    driver reports the CLOSE executed); **tracking** in q0 with activity tracking, or in q1
///    (sg-grasp waiting to close: the arm follows the ball at its stand-off); **idle** otherwise
///    (q0 idle, homing, backing off; q3 or q4 with SIM_ARM_STATE saying the hand is empty).
///
/// A SIM_ARM_STATE is fresh for kSimFresh (1 s) after it is received. Times are receive times
/// (the logger's one clock, whatever the processes' clocks say). The phase changes are kept, the
/// last kMaxChanges of them, so a log of any length costs the same memory.

#include <cstdint>
#include <deque>
#include <optional>
#include <utility>

namespace sg::logger {

/// A moment's phase. The order is the report's.
enum class Phase { kNoGraspMachine, kCalibration, kIdle, kTracking, kApproach, kCarried };
constexpr int kPhaseCount = 6;

/// "no grasp machine", "calibration", "idle", "tracking", "approach", "carried".
const char* phase_name(Phase phase);
/// The same with underscores, for report.json: "no_grasp_machine", ...
const char* phase_key(Phase phase);
/// True for the phases in which the arm holds the ball (the calibration, the carried ball): the
/// ball does not follow its own path there, and figure 5 leaves them out.
inline bool holds_the_ball(Phase phase) {
  return phase == Phase::kCalibration || phase == Phase::kCarried;
}

/// Follows the phase of a session through its log.
class SessionPhase {
 public:
  static constexpr int64_t kSimFresh = 1'000'000;  ///< us a SIM_ARM_STATE stands for
  static constexpr size_t kMaxChanges = 4096;

  /// Moves the clock to `recv` (receive times in log order); true when the phase changed (a
  /// SIM_ARM_STATE went stale).
  bool advance(int64_t recv);
  /// GRASP_STATUS's state (Q0..Q4) and activity; true when the phase changed.
  bool on_grasp_status(int64_t recv, int state, int activity);
  /// SIM_ARM_STATE's holding_object; true when the phase changed.
  bool on_sim_arm_state(int64_t recv, bool holding);
  /// Any ARM_COMMAND; true when the phase changed.
  bool on_arm_command(int64_t recv);

  Phase current() const { return current_; }
  /// The phase at receive time `recv` (up to the last event seen; later times give the current
  /// one), or nothing for a time before the changes kept.
  std::optional<Phase> at(int64_t recv) const;
  /// Seconds spent in `phase`, from the first event to the last one seen.
  double seconds_in(Phase phase) const;

 private:
  Phase rule() const;
  bool update(int64_t recv);

  bool started_ = false;
  int64_t last_recv_ = 0;
  Phase current_ = Phase::kNoGraspMachine;
  std::deque<std::pair<int64_t, Phase>> changes_;  // (receive time, phase from then on)
  bool trimmed_ = false;                           // changes_ lost its oldest entries
  double time_in_[kPhaseCount] = {};               // us; in double: a log's times may be any int64
  // what the rule reads
  bool have_grasp_ = false, arm_commanded_ = false;
  int state_ = 0, activity_ = 0;
  bool have_sim_ = false, holding_ = false;
  int64_t sim_recv_ = 0;
};

}  // namespace sg::logger
