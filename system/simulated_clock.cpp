#include "system/simulated_clock.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace sg::system {

int64_t SimulatedClock::utime_at(double t) const { return epoch_utime_ + std::llround(t * 1e6); }

double SimulatedClock::time_of(int64_t utime) const {
  return static_cast<double>(utime - epoch_utime_) * 1e-6;
}

void SimulatedClock::at(double t, Event event) {
  events_.emplace(std::pair(std::max(t, now_), next_id_++), std::move(event));
}

void SimulatedClock::every(double period, Event event, double first) {
  if (!(period > 0)) throw std::invalid_argument("SimulatedClock::every: period must be positive");
  schedule(std::make_shared<Periodic>(Periodic{std::move(event), period, first, 0}));
}

void SimulatedClock::schedule(std::shared_ptr<Periodic> p) {
  // The k-th run is at first + k * period, so rounding does not accumulate.
  const double t = p->first + static_cast<double>(p->k) * p->period;
  at(t, [this, p](double now) {
    p->event(now);
    ++p->k;
    schedule(p);
  });
}

double SimulatedClock::next_event_time() const {
  return events_.empty() ? std::numeric_limits<double>::infinity() : events_.begin()->first.first;
}

bool SimulatedClock::run_next(double deadline) {
  if (events_.empty() || events_.begin()->first.first > deadline) return false;
  auto node = events_.extract(events_.begin());
  now_ = std::max(now_, node.key().first);
  ++events_run_;
  node.mapped()(now_);
  return true;
}

bool SimulatedClock::wait_until(std::unique_lock<std::mutex>& lock, double deadline,
                                const std::function<bool()>& ready, std::stop_token stop) {
  while (!ready()) {
    if (stop.stop_requested()) return false;
    lock.unlock();
    const bool ran = run_next(deadline);
    lock.lock();
    if (!ran) {
      if (std::isfinite(deadline)) now_ = std::max(now_, deadline);
      return ready();
    }
  }
  return true;
}

void SimulatedClock::sleep_until(double deadline) {
  while (run_next(deadline)) {
  }
  if (std::isfinite(deadline)) now_ = std::max(now_, deadline);
}

}  // namespace sg::system
