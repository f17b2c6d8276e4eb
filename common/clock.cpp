#include "common/clock.hpp"

#include <chrono>
#include <cmath>
#include <thread>

namespace sg {
namespace {

using Steady = std::chrono::steady_clock;

/// A steady_clock time point `seconds` after its epoch (clamped an hour ahead for +infinity).
Steady::time_point steady_at(double seconds, double now) {
  const double s = std::isfinite(seconds) ? seconds : now + 3600.0;
  return Steady::time_point(std::chrono::duration_cast<Steady::duration>(
      std::chrono::duration<double>(s)));
}

}  // namespace

int64_t now_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

double SystemClock::now() {
  return std::chrono::duration<double>(Steady::now().time_since_epoch()).count();
}

bool SystemClock::wait_until(std::unique_lock<std::mutex>& lock, double deadline,
                             const std::function<bool()>& ready, std::stop_token stop) {
  while (!ready()) {
    const double t = now();
    if (t >= deadline || stop.stop_requested()) return false;
    // At most an hour at a time, so an infinite deadline still re-checks now and then.
    wake_.wait_until(lock, stop, steady_at(std::min(deadline, t + 3600.0), t), ready);
  }
  return true;
}

void SystemClock::notify() { wake_.notify_all(); }

void SystemClock::sleep_until(double deadline) {
  const double t = now();
  if (deadline > t) std::this_thread::sleep_until(steady_at(deadline, t));
}

SystemClock& system_clock() {
  static SystemClock clock;
  return clock;
}

}  // namespace sg
