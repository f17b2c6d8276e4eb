#include "system/simulated_line.hpp"

#include <gtest/gtest.h>

#include "arm_driver/c550_link.hpp"
#include "arm_driver/rapl.hpp"
#include "sim/c550_controller.hpp"

namespace sg::system {
namespace {

/// The host side of the real driver, talking to the emulator over a simulated line.
struct Bench {
  explicit Bench(int baud)
      : clock(0),
        controller(arm::ArmGeometry::a465()),
        emulator(controller),
        line(emulator, clock, {baud, {}}),
        link(line, 1, {}, clock) {}
  SimulatedClock clock;
  sim::C550Controller controller;
  sim::C550Emulator emulator;
  SimulatedLine line;
  arm::C550Link link;
};

// The driver's session opens over the simulated line as over a pseudo-terminal.
TEST(SimulatedLine, LinkOpensTheSession) {
  Bench b(38400);
  b.link.open_session();
  EXPECT_TRUE(b.emulator.in_session());
  EXPECT_EQ(b.emulator.executed_commands(), (std::vector<std::string>{"NOH"}));
}

// A command that answers at once takes one byte time (10 bits / baud) per byte each way: every
// character waits for its echo, and the reply follows back to back.
TEST(SimulatedLine, ImmediateCommandTakesItsBytesOnTheWire) {
  for (int baud : {9600, 38400}) {
    Bench b(baud);
    b.link.open_session();
    const uint64_t written = b.line.bytes_written(), read = b.line.bytes_read();
    const double start = b.clock.now();
    (void)b.link.read_joints();  // W2
    const double bytes = static_cast<double>(b.line.bytes_written() - written +
                                             b.line.bytes_read() - read);
    EXPECT_NEAR(b.clock.now() - start, bytes * 10.0 / baud, 1e-9) << baud << " baud";
  }
}

// A motion command is answered one interaction delay (0.72-0.84 s) after its CR arrives, and the
// arm starts moving then.
TEST(SimulatedLine, MotionCommandAnswersAfterTheInteractionDelay) {
  Bench b(38400);
  b.link.open_session();
  arm::rapl::JointArray target{0.2, 0.1, 1.4, 0.0, 1.5, 0.0};
  const double start = b.clock.now();
  b.link.command(arm::rapl::move_joints(target), arm::LinkTiming{}.motion_reply);
  const double took = b.clock.now() - start;
  EXPECT_GT(took, 0.72);
  EXPECT_LT(took, 0.84 + 0.05);  // + the line's bytes
  EXPECT_NEAR(b.controller.last_motion_start(), b.clock.now(), 0.01);
}

// A read with nothing to come times out after exactly its time-out, in simulated time.
TEST(SimulatedLine, SilentReadTimesOut) {
  Bench b(38400);
  const double start = b.clock.now();
  EXPECT_FALSE(b.line.read_byte(std::chrono::milliseconds(200)));
  EXPECT_DOUBLE_EQ(b.clock.now() - start, 0.2);
}

}  // namespace
}  // namespace sg::system
