#include "system/simulated_line.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace sg::system {
namespace {

/// A ByteStream that forwards to a SimulatedLine it does not own.
class LineHandle final : public arm::ByteStream {
 public:
  explicit LineHandle(arm::ByteStream& line) : line_(line) {}
  void write(std::span<const uint8_t> bytes) override { line_.write(bytes); }
  std::optional<uint8_t> read_byte(std::chrono::microseconds timeout) override {
    return line_.read_byte(timeout);
  }
  void discard_input() override { line_.discard_input(); }

 private:
  arm::ByteStream& line_;
};

}  // namespace

SimulatedLine::SimulatedLine(sim::C550Emulator& emulator, SimulatedClock& clock,
                             SimulatedLineSettings settings)
    : emulator_(emulator), clock_(clock), settings_(std::move(settings)) {
  if (settings_.baud < 300) throw std::invalid_argument("simulated line: baud below 300");
}

std::unique_ptr<arm::ByteStream> SimulatedLine::connect() {
  return std::make_unique<LineHandle>(*this);
}

void SimulatedLine::write(std::span<const uint8_t> bytes) {
  for (const uint8_t b : bytes) {
    tx_free_ = std::max(tx_free_, clock_.now()) + byte_time();
    to_controller_.push_back({tx_free_, b});
  }
  bytes_written_ += bytes.size();
}

void SimulatedLine::pump() {
  // Step through what happened since the last pump in time order: each byte reaches the
  // emulator when it has crossed the wire, and each answer starts on the wire when it was due.
  const double now = clock_.now();
  for (int guard = 0; guard < 1'000'000; ++guard) {
    double t = emulator_.next_output_time();
    if (!to_controller_.empty()) t = std::min(t, to_controller_.front().t);
    if (!(t <= now)) return;
    if (settings_.before_pump) settings_.before_pump(t);
    while (!to_controller_.empty() && to_controller_.front().t <= t) {
      emulator_.feed(to_controller_.front().byte, to_controller_.front().t);
      to_controller_.pop_front();
    }
    for (const uint8_t b : emulator_.take_output(t)) {
      rx_free_ = std::max(rx_free_, t) + byte_time();
      to_host_.push_back({rx_free_, b});
    }
  }
  throw std::logic_error("simulated line: the emulator's output does not advance");
}

double SimulatedLine::next_change() const {
  double t = emulator_.next_output_time();
  if (!to_controller_.empty()) t = std::min(t, to_controller_.front().t);
  if (!to_host_.empty()) t = std::min(t, to_host_.front().t);
  return t;
}

std::optional<uint8_t> SimulatedLine::read_byte(std::chrono::microseconds timeout) {
  const double deadline = clock_.now() + std::chrono::duration<double>(timeout).count();
  for (;;) {
    pump();
    if (!to_host_.empty() && to_host_.front().t <= clock_.now()) {
      const uint8_t b = to_host_.front().byte;
      to_host_.pop_front();
      ++bytes_read_;
      return b;
    }
    if (clock_.now() >= deadline) return std::nullopt;
    clock_.sleep_until(std::min(deadline, std::max(next_change(), clock_.now())));
  }
}

void SimulatedLine::discard_input() {
  pump();
  while (!to_host_.empty() && to_host_.front().t <= clock_.now()) to_host_.pop_front();
}

}  // namespace sg::system
