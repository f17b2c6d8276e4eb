#include "arm_driver/log_limiter.hpp"

namespace sg::arm {

bool LogLimiter::allow(const std::string& kind, double t, uint64_t& suppressed) {
  Kind& k = kinds_[kind];
  const bool pass = ++k.seen <= static_cast<uint64_t>(burst_) || t - k.last_logged >= period_;
  if (!pass) {
    ++k.suppressed;
    return false;
  }
  suppressed = k.suppressed;
  k.suppressed = 0;
  k.last_logged = t;
  return true;
}

}  // namespace sg::arm
