#include "sim/fault_injector.hpp"

namespace sg::sim {

void FaultInjector::apply(const C550Emulator::Chunk& chunk, std::deque<uint8_t>& out) {
  if (chunk.ack && chance(drop_ack_rate_)) {
    ++dropped_;
    return;
  }
  for (uint8_t byte : chunk.bytes) {
    if (chance(garble_rate_)) {
      byte = static_cast<uint8_t>(byte + 1 + rng_() % 255);  // any value but the original
      ++garbled_;
    }
    out.push_back(byte);
  }
}

}  // namespace sg::sim
