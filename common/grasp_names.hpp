#pragma once

/// The names of grasp_status_t's enumerations (the paper's figure 4) and command results, one list
/// for the grasp machine, sg-grasp-ctl and sg-report. Values outside a list give "unknown".
///
///     std::printf("%s\n", sg::grasp_state_name(status.state));   // "q3 hand closed"

namespace sg {

/// Q0_HAND_OPENED .. Q4_OBJECT_LIFTED.
inline const char* grasp_state_name(int state) {
  static const char* const names[] = {"q0 hand opened", "q1 approaching", "q2 grasping",
                                      "q3 hand closed", "q4 object lifted"};
  return state >= 0 && state <= 4 ? names[state] : "unknown";
}

/// ACTIVITY_IDLE .. ACTIVITY_BACKING_OFF.
inline const char* grasp_activity_name(int activity) {
  static const char* const names[] = {"idle", "tracking", "grasping", "homing", "backing off"};
  return activity >= 0 && activity <= 4 ? names[activity] : "unknown";
}

/// ACTION_NONE (-1), A0_OPEN_HAND .. A3_LIFT_OBJECT.
inline const char* grasp_action_name(int action) {
  static const char* const names[] = {"none", "a0 open hand", "a1 approach object", "a2 close hand",
                                      "a3 lift object"};
  return action >= -1 && action <= 3 ? names[action + 1] : "unknown";
}

/// OUTCOME_NONE .. OUTCOME_ABORTED.
inline const char* grasp_outcome_name(int outcome) {
  static const char* const names[] = {"none", "success", "failed", "aborted"};
  return outcome >= 0 && outcome <= 3 ? names[outcome] : "unknown";
}

/// RESULT_NONE .. RESULT_REFUSED_UNAUTHENTICATED: what became of the last GRASP_COMMAND.
inline const char* grasp_command_result_name(int result) {
  static const char* const names[] = {"none",
                                      "accepted",
                                      "refused: not newer",
                                      "refused: unknown command",
                                      "refused: bad argument",
                                      "refused: state",
                                      "refused: unauthenticated"};
  return result >= 0 && result <= 6 ? names[result] : "unknown";
}

}  // namespace sg
