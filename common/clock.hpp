#pragma once

/// Time for the code that has to wait. A process's main loop reads the wall clock
/// (now_utime()); a component that waits — the arm driver between interactions, the C550 link
/// for an echo or a settle time — takes a Clock, so the same code runs against the machine's
/// clocks in a process and against a simulated clock in the in-process trials
/// (system/simulated_clock.hpp), where waiting means running the simulated world up to the
/// deadline.
///
///     sg::Clock& clock = sg::system_clock();          // or a SimulatedClock
///     std::unique_lock lock(mutex);
///     clock.wait_until(lock, clock.now() + 0.5, [&] { return work_ready; }, stop);
///     clock.notify();                                  // from whoever made work ready

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stop_token>

namespace sg {

/// Wall-clock time in microseconds since the Unix epoch, the unit of every message's `utime`.
///
/// Only a process's main loop may call this (DESIGN rule 1): algorithms take time from the
/// messages they are given, so a replayed log gives the same outputs.
int64_t now_utime();

/// A source of time that can also be waited on.
class Clock {
 public:
  virtual ~Clock() = default;

  /// Seconds on a monotonic axis (intervals and time-outs).
  virtual double now() = 0;
  /// Microseconds since the Unix epoch at now() (message time stamps).
  virtual int64_t utime() = 0;

  /// Blocks until `ready()` holds, `deadline` (now() seconds) has come, or `stop` is requested;
  /// returns ready(). `lock` is held on entry and on return and released while waiting, so the
  /// code that makes `ready()` true can take it; `ready` is evaluated under it. A SystemClock
  /// re-checks on notify(); a SimulatedClock after each simulated event.
  virtual bool wait_until(std::unique_lock<std::mutex>& lock, double deadline,
                          const std::function<bool()>& ready, std::stop_token stop = {}) = 0;
  /// Wakes the waiters of wait_until() to re-check their conditions.
  virtual void notify() = 0;
  /// Waits until `deadline` with nothing to wake for.
  virtual void sleep_until(double deadline) = 0;

  void sleep_for(double seconds) { sleep_until(now() + seconds); }
};

/// The machine's clocks: std::chrono::steady_clock for now(), the system clock for utime().
class SystemClock final : public Clock {
 public:
  double now() override;
  int64_t utime() override { return now_utime(); }
  bool wait_until(std::unique_lock<std::mutex>& lock, double deadline,
                  const std::function<bool()>& ready, std::stop_token stop = {}) override;
  void notify() override;
  void sleep_until(double deadline) override;

 private:
  std::condition_variable_any wake_;
};

/// The process's one SystemClock, the default of every component that takes a Clock.
SystemClock& system_clock();

}  // namespace sg
