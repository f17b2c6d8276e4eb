#include "grasp/grasp_settings.hpp"

namespace sg::grasp {

GraspSettings read_grasp_settings(const Config& config) {
  GraspSettings s;
  InterceptionSettings& i = s.interception;
  Section g(config, "grasp");
  g.number("standoff", s.standoff, Range::closed(0, 0.5), "m above the ball while tracking");
  g.number("lift", s.lift, Range::above_to(0, 0.5), "m the object is lifted (a3)");
  g.number("backoff", s.backoff, Range::closed(0, 0.5),
           "m the tool rises when the track is lost during an approach");
  g.number("speed", s.speed, Range::above_to(0, 1), "fraction of the joint speed limits");
  g.number("max_trajectory_age", s.max_trajectory_age, Range::above_to(0, 60),
           "s: an older OBJECT_TRAJECTORY gives no command");
  g.number("success_distance", s.success_distance, Range::above_to(0, 1),
           "m: after the lift, the measured ball this close to the tool = held");
  g.number("judge_time", s.judge_time, Range::above_to(0, 60),
           "s after the arm stops: no sighting that close by then = not held");
  g.number("default_delay", s.default_delay, Range::above_to(0, 10),
           "s per controller command until ARM_STATUS has measured one");
  g.number("heartbeat_period", s.heartbeat_period, Range::closed(0.01, 1.0),
           "s between ARM_COMMAND heartbeats while sg-grasp wants the arm (keep it well below "
           "arm_driver.commander_timeout)");
  g.number("resend_after", s.resend_after, Range::closed(0.05, 10),
           "s: a request that ARM_STATUS does not show received is sent again (same sequence)");
  g.number("arm_status_timeout", s.arm_status_timeout, Range::closed(0.1, 60),
           "s without ARM_STATUS: no request and no heartbeat until it returns");
  g.number("tolerance", s.tolerance, Range::above_to(0, 0.5),
           "m: the ball centre this close to the tool centre at the close still grasps");
  g.number("confidence", s.confidence, Range::closed(0, 10),
           "sigmas of the close's predicted error that must fit in the tolerance (0: close "
           "at once)");
  g.number("arm_sigma", s.arm_sigma, Range::closed(0, 0.5),
           "m: the arm's and the calibration's 1-sigma error at the tool (3D)");
  g.number("timing_sigma", s.timing_sigma, Range::closed(0, 5),
           "s: the 1-sigma spread of the controller's delay per interaction");
  g.number("max_wait", s.max_wait, Range::closed(0, 600),
           "s after the grasp command: close on the best guess when no interception was sure");
  g.number("replan_shift", s.replan_shift, Range::above_to(0, 1),
           "m: a newer forecast moving the ball at the approach's arrival time this far re-plans "
           "the approach");
  g.number("replan_margin", s.replan_margin, Range::closed(0, 10),
           "s: re-plan only until one delay less this after the approach was sent (the CLOSE "
           "can then still give way in the driver)");
  g.number("max_replans", s.max_replans, Range::closed(0, 100),
           "re-plans of the approach a grasp (0: never)");
  g.flag("use_prediction", s.use_prediction,
         "false: aim at the last measured position (the baseline)");
  g.number("table_z", i.table_z, Range::closed(-2, 2), "m: the table top in the robot's frame");
  g.number("table_margin", i.table_margin, Range::closed(0, 0.5),
           "m the tool centre point stays above the table");
  g.number("wrist_min", i.wrist_min, Range::above_to(0, 2),
           "m: the approach leans so the wrist centre stays this far from the shoulder ...");
  g.number("wrist_max", i.wrist_max, Range::above_to(0, 2), "m: ... and no farther");
  if (!(i.wrist_min < i.wrist_max)) throw g.error("wrist_min", "must be below wrist_max");
  InputGate& in = s.input_gate;
  g.number("position_margin", in.margin, Range::closed(0, 2),
           "m: an OBJECT_TRAJECTORY point farther than this outside the arm's workspace "
           "(arm.workspace_min/max) refuses the trajectory");
  g.number("max_time_offset", in.max_time_offset, Range::closed(0, 3600),
           "s: an OBJECT_TRAJECTORY whose utime or start_utime is farther than this from the "
           "receiver's clock is refused (0: not checked, for replays of old logs)");
  g.done();
  return s;
}

}  // namespace sg::grasp
