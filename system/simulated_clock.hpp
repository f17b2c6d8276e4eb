#pragma once

/// Simulated time for the in-process trials: a discrete-event scheduler behind the sg::Clock
/// interface. Whoever waits on it — the arm driver's worker between interactions, the C550 link
/// for an echo — runs the simulated world's events (camera frames, the grasp process's loop, the
/// driver's status publications, bus deliveries) in time order up to its deadline, or until its
/// condition holds. One thread; deterministic: events at the same time run in the order they
/// were scheduled.
///
///     SimulatedClock clock(kTrialEpochUtime);
///     clock.every(0.25, [&](double t) { capture_frame(t); });      // 4 Hz frames
///     clock.at(45.0, [&](double) { operator_grasps(); });
///     ArmDriver driver(geometry, settings, open_line, clock);       // waits run the world
///     driver.run(stop);                                             // until an event stops it

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <utility>

#include "common/clock.hpp"

namespace sg::system {

class SimulatedClock final : public Clock {
 public:
  using Event = std::function<void(double now)>;

  /// Time 0 of the simulation is `epoch_utime` microseconds since the Unix epoch.
  explicit SimulatedClock(int64_t epoch_utime) : epoch_utime_(epoch_utime) {}

  double now() override { return now_; }
  int64_t utime() override { return utime_at(now_); }
  int64_t utime_at(double t) const;
  double time_of(int64_t utime) const;

  /// Runs `event` at `t` (now, when `t` is in the past).
  void at(double t, Event event);
  /// Runs `event` at `first`, then every `period` seconds (> 0) for ever.
  void every(double period, Event event, double first = 0.0);

  /// Runs every event due up to `deadline` in order, stopping early when `ready()` holds (checked
  /// before the first and after each event) or `stop` is requested; time then stands at the last
  /// event run, or at `deadline` when ready() never held. `lock` is released while events run.
  bool wait_until(std::unique_lock<std::mutex>& lock, double deadline,
                  const std::function<bool()>& ready, std::stop_token stop = {}) override;
  void notify() override {}  // waiters re-check after every event anyway
  void sleep_until(double deadline) override;

  /// The time of the next event; +infinity when none.
  double next_event_time() const;
  /// Events run so far.
  uint64_t events_run() const { return events_run_; }

 private:
  struct Periodic {
    Event event;
    double period = 0;
    double first = 0;
    int64_t k = 0;  ///< runs so far
  };
  void schedule(std::shared_ptr<Periodic> p);
  /// Runs the next event if it is due by `deadline`; false when none is.
  bool run_next(double deadline);

  int64_t epoch_utime_;
  double now_ = 0;
  uint64_t next_id_ = 0;
  uint64_t events_run_ = 0;
  std::map<std::pair<double, uint64_t>, Event> events_;
};

}  // namespace sg::system
