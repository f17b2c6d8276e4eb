// sg-c550-sim: a CRS C550 controller and its arm on a pseudo-terminal (docs/arm.md). sg-arm-driver
// opens the printed /dev/pts/N (or the --link path) as it would a real serial port. Publishes the
// arm's true state on SIM_ARM_STATE for sg-camera-sim, and grasps the ball GROUND_TRUTH says is
// there. Fault injection (garbled bytes, lost ACKs, a line that drops and comes back) tests the
// driver's recovery.
//
//   sg-c550-sim --link /tmp/c550                   # then: sg-arm-driver --device /tmp/c550
//   sg-c550-sim --garble-rate 0.001 --drop-ack-rate 0.01 --log-commands commands.tsv
//   sg-c550-sim --disconnect-after 5 --reconnect-after 2
//   sg-c550-sim --link /tmp/c550 --holding         # the ball in the gripper (robot calibration)

#include <algorithm>

#include "arm_driver/kinematics.hpp"
#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "sim/c550_sim_settings.hpp"
#include "sim/c550_sim_shell.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "A simulated CRS C550 controller and arm on a pseudo-terminal: the ACI link layer and "
      "RAPL-II commands of docs/arm.md, for sg-arm-driver. Prints 'sg-c550-sim: serial device "
      "/dev/pts/N'; publishes SIM_ARM_STATE; grasps the GROUND_TRUTH ball. Every flag can also "
      "be set under 'c550_sim:' in --config (same name, with _ for -); flags win.",
      "sg-c550-sim"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  const auto keys = sg::declared_keys(sg::sim::read_c550_sim_settings);
  for (const char* key :
       {"slave", "delay_min", "delay_max", "speed", "seed", "link", "garble_rate", "drop_ack_rate",
        "disconnect_after", "reconnect_after", "log_commands", "state_rate"}) {
    std::string flag = std::string("--") + key;
    std::replace(flag.begin(), flag.end(), '_', '-');
    common.flags.add(app, flag, std::string("c550_sim.") + key, keys);
  }
  common.flags.add_switch(app, "--holding", "c550_sim.holding", "true",
                          "start with the gripper closed on the ball (SIM_ARM_STATE "
                          "holding_object, so sg-camera-sim draws the ball at the tool centre "
                          "point) until the first OPEN: for sg-calibrate robot");

  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    const sg::sim::C550SimSettings settings = sg::sim::read_c550_sim_settings(config);
    sg::install_shutdown_handlers();
    sg::sim::C550Controller controller(sg::arm::load_arm_geometry(config), settings.controller);
    return sg::auth::with_lab_access(app.get_name(), key_options, [&](auto& lab) {
      sg::Bus bus(common.lcm_url);
      lab.guard(bus);  // believes GROUND_TRUTH only from sg-camera-sim
      bus.announce("sg-c550-sim");
      sg::sim::C550SimShell shell(settings, controller, bus);
      return shell.run();
    });
  });
}
