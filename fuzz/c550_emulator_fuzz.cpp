// Drives the C550 emulator (sim/c550_emulator.hpp), what sg-c550-sim runs on its pseudo-terminal,
// with what a host may write: the input is pairs (gap, byte), each byte arriving 0.26 ms
// (38,400 baud) plus `gap` ms after the previous one, so the fuzzer reaches the 100 ms
// inter-character time-out and the held motion replies; after the last byte ten simulated
// seconds pass. Output is collected after every byte, as the shell does.
// Asserts, beyond not crashing:
//  - feed() and take_output() throw nothing (a host's bytes must not kill the simulator);
//  - nothing is output before it is due (next_output_time() > t after take_output(t)), and all
//    is out at the end;
//  - the arm's joints stay within the A465's limits at every byte (the emulator refuses motions
//    outside them), and are finite;
//  - every executed command line is at most kMaxLine characters (plus "..." when cut) and holds no
//    CR or LF.

#include <cmath>
#include <cstdint>
#include <limits>

#include "arm_driver/kinematics.hpp"
#include "arm_driver/rapl.hpp"
#include "fuzz/fuzz_support.hpp"
#include "sim/c550_controller.hpp"
#include "sim/c550_emulator.hpp"

namespace {

void check_arm(const sg::sim::C550Controller& controller, double t) {
  const sg::arm::Joints q = controller.joints(t);
  SG_FUZZ_CHECK(q.allFinite(), "joints not finite at t = %g", t);
  SG_FUZZ_CHECK(sg::arm::within_limits(controller.geometry(), q), "joints outside the limits");
}

void collect(sg::sim::C550Emulator& c550, double t) {
  (void)c550.take_output(t);
  SG_FUZZ_CHECK(c550.next_output_time() > t, "output due at %g left after take_output(%g)",
                c550.next_output_time(), t);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::sim::C550Controller controller(sg::arm::ArmGeometry::a465());
  sg::sim::C550Emulator c550(controller, 1);
  double t = 0;
  for (size_t i = 0; i + 1 < size; i += 2) {
    t += 10.0 / 38400 + data[i] * 1e-3;
    c550.feed(data[i + 1], t);
    collect(c550, t);
    check_arm(controller, t);
  }
  t += 10.0;
  collect(c550, t);
  (void)c550.take_events();
  SG_FUZZ_CHECK(c550.next_output_time() == std::numeric_limits<double>::infinity(),
                "output still queued ten seconds after the last byte");
  check_arm(controller, t);
  for (const std::string& line : c550.executed_commands()) {
    SG_FUZZ_CHECK(line.size() <= sg::arm::rapl::kMaxLine + 3, "executed line of %zu", line.size());
    SG_FUZZ_CHECK(line.find_first_of("\r\n") == std::string::npos, "CR/LF in '%s'", line.c_str());
  }
  return 0;
}
