#include "sim/c550_sim_settings.hpp"

namespace sg::sim {

C550SimSettings read_c550_sim_settings(const Config& config) {
  C550SimSettings s;
  C550Params& p = s.controller;
  LineFaults& f = s.faults;
  Section c(config, "c550_sim");
  c.number("slave", s.slave, Range::closed(1, 127), "ACI slave number");
  c.number("delay_min", p.delay_min, Range::closed(0, 60),
           "s: the shortest delay from a motion command to its ACK");
  c.number("delay_max", p.delay_max, Range::closed(0, 60), "s: the longest such delay");
  if (!(p.delay_min <= p.delay_max)) throw c.error("delay_max", "must be at least delay_min");
  c.number("speed", p.speed_percent, Range::closed(1, 100), "SPEED at power-up, percent");
  int64_t seed = p.seed;
  c.number("seed", seed, Range::closed(0, 4294967295.0),
           "seed of the delay draws and the fault injection");
  p.seed = static_cast<uint32_t>(seed);
  c.text("link", s.link,
         "make PATH a symlink to the pseudo-terminal (re-pointed on reconnect, removed at exit)");
  c.number("garble_rate", f.garble_rate, Range::closed(0, 1),
           "probability that a byte the controller sends is replaced by a random one");
  c.number("drop_ack_rate", f.drop_ack_rate, Range::closed(0, 1),
           "probability that an ACK the controller sends is lost");
  c.number("disconnect_after", f.disconnect_after, Range::closed(0, 86400),
           "close the pseudo-terminal after S seconds, then open a new one (arm state kept, line "
           "back in ACI mode); 0: never");
  c.number("reconnect_after", f.reconnect_after, Range::closed(0, 3600),
           "seconds without a line after disconnect_after");
  c.text("log_commands", s.log_commands,
         "append each RAPL command line received to FILE: utime, seconds since start, command, "
         "tab-separated");
  c.number("state_rate", s.state_rate, Range::above_to(0, 1000), "SIM_ARM_STATE messages per second");
  c.number("gripper_time", p.gripper_time, Range::above_to(0, 60), "s to open or close");
  c.number("gripper_open_width", p.gripper_open_width, Range::above_to(0, 1), "m between the fingers");
  c.number("gripper_closed_width", p.gripper_closed_width, Range::closed(0, 1),
           "m between the fingers closed on nothing");
  c.number("grasp_tolerance", p.grasp_tolerance, Range::above_to(0, 1),
           "m: the gripper centre within this of the ball's centre holds it");
  c.number("ball_radius", p.ball_radius, Range::above_to(0, 1), "m");
  c.flag("holding", p.start_holding,
         "start with the gripper closed on the ball until the first OPEN (sg-calibrate robot)");
  c.done();
  return s;
}

}  // namespace sg::sim
