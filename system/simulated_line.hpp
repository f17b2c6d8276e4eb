#pragma once

/// The serial line between the arm driver and the C550 emulator, in simulated time: the
/// in-process counterpart of sg-c550-sim's pseudo-terminal. The driver's C550Link writes and
/// reads the very bytes it would send to /dev/ttyS0; each byte takes 10 bit times on the wire
/// (8N1 at `baud`), the emulator sees it when it has arrived and answers when its model says
/// (echoes at once, a motion command's ACK one interaction delay later). A read that must wait
/// runs the simulated world (SimulatedClock::sleep_until) until the next byte can have arrived
/// or the time-out has passed.
///
///     SimulatedClock clock(epoch);
///     C550Controller controller(geometry, params);
///     C550Emulator emulator(controller);
///     SimulatedLine line(emulator, clock, {.before_pump = [&](double t) {
///       emulator.set_ball_centre(world.ball_at(t)); }});
///     C550Link link(line, 1, {}, clock);  // or ArmDriver(..., [&] { return line.connect(); },
///     clock)

#include <deque>
#include <functional>
#include <memory>

#include "arm_driver/byte_stream.hpp"
#include "sim/c550_emulator.hpp"
#include "system/simulated_clock.hpp"

namespace sg::system {

struct SimulatedLineSettings {
  int baud = 38400;  ///< 10 bits a byte (8N1): 0.26 ms at 38,400 baud
  /// Called before the emulator sees time `t` (a byte arrives, its output is collected), e.g. to
  /// tell it where the ball is for a CLOSE.
  std::function<void(double t)> before_pump;
};

class SimulatedLine final : public arm::ByteStream {
 public:
  SimulatedLine(sim::C550Emulator& emulator, SimulatedClock& clock,
                SimulatedLineSettings settings = {});

  void write(std::span<const uint8_t> bytes) override;
  std::optional<uint8_t> read_byte(std::chrono::microseconds timeout) override;
  void discard_input() override;

  /// A ByteStream for ArmDriver's DeviceOpener: the same line (the emulator keeps its state, as a
  /// controller does when a driver reconnects); it stays valid while this object lives.
  std::unique_ptr<arm::ByteStream> connect();

  uint64_t bytes_written() const { return bytes_written_; }
  uint64_t bytes_read() const { return bytes_read_; }

 private:
  struct Timed {
    double t = 0;  ///< when the byte has crossed the wire
    uint8_t byte = 0;
  };
  double byte_time() const { return 10.0 / settings_.baud; }
  /// Feeds the emulator what has arrived by now and moves its due output onto the wire.
  void pump();
  /// When something can next change for a reader: a byte arriving either way, or the
  /// emulator's next output.
  double next_change() const;

  sim::C550Emulator& emulator_;
  SimulatedClock& clock_;
  SimulatedLineSettings settings_;
  std::deque<Timed> to_controller_;
  std::deque<Timed> to_host_;
  double tx_free_ = 0;  ///< when the host's transmitter is free again
  double rx_free_ = 0;  ///< when the controller's transmitter is free again
  uint64_t bytes_written_ = 0;
  uint64_t bytes_read_ = 0;
};

}  // namespace sg::system
