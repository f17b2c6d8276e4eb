#pragma once

#include <cstdint>
#include <deque>
#include <random>

#include "sim/c550_emulator.hpp"

namespace sg::sim {

/// The line faults sg-c550-sim injects into what the controller sends: each byte replaced by
/// another with probability `garble_rate`, each ACK lost with probability `drop_ack_rate`, drawn
/// from its own generator seeded with `seed` (so a seed gives the same faults every run).
class FaultInjector {
 public:
  FaultInjector(double garble_rate, double drop_ack_rate, uint32_t seed)
      : garble_rate_(garble_rate), drop_ack_rate_(drop_ack_rate), rng_(seed) {}

  /// Appends `chunk` to `out` with its faults: nothing for a dropped ACK, else its bytes with
  /// each garbled one replaced by a different value.
  void apply(const C550Emulator::Chunk& chunk, std::deque<uint8_t>& out);

  int64_t garbled() const { return garbled_; }  ///< bytes replaced so far
  int64_t dropped() const { return dropped_; }  ///< ACKs lost so far

 private:
  bool chance(double p) { return p > 0 && static_cast<double>(rng_()) / 4294967296.0 < p; }

  double garble_rate_, drop_ack_rate_;
  std::mt19937 rng_;
  int64_t garbled_ = 0, dropped_ = 0;
};

}  // namespace sg::sim
