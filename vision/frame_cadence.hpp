#pragma once

/// When the next stereo pair is due, from when the last ones came, so that sg-vision's thread is
/// awake for it (issue 19). A thread that sleeps in poll() until a frame arrives must first be
/// woken; on the lab's 2-vCPU virtual machine that took about 0.1 ms at the median and up to
/// 1 ms in 6 % of pairs (the vCPU itself halted and woken by the host), the largest part of
/// sg-vision's p99 (docs/performance.md). A camera is periodic, so the wait can be split: sleep
/// until shortly before the pair is due, then poll without sleeping until it comes.
/// (sg-vision now keeps its decode workers polling in that window and lets its reading thread
/// sleep: a worker woken for a pair's first image was the larger delay; decode_worker.hpp.)
///
///     FrameCadence cadence(std::chrono::microseconds(1000));  // awake 1 ms either side
///     for (;;) {
///       bus.handle(cadence.sleep_before_next(clock::now(), 100ms));  // 0: poll, do not sleep
///       if (a pair completed) cadence.arrived(when it began);
///     }
///
/// The thread is awake from `awake` before the earliest the next pair may come until `awake`
/// after the latest: a pair has come between the shortest and the longest of the last 15
/// intervals after its predecessor (the ordinary ones, within half and one and a half times
/// their median; a stall or the burst after it counts not). A whole period later for each
/// frame lost, so a missed frame still finds the thread awake for the next; between windows,
/// and before three intervals are known, it sleeps. The cost is the CPU time of the waiting:
/// the spread of the intervals and 2 x awake, per pair (on the lab's VM frames came 47-52 ms
/// apart at 20 Hz: 7 ms of 50 with 1 ms awake). After 10 periods without a pair (the cameras
/// stopped) it sleeps until the next.

#include <array>
#include <chrono>
#include <cstddef>

namespace sg::vision {

class FrameCadence {
 public:
  using Clock = std::chrono::steady_clock;

  /// `awake`: how long before and after a pair is due sg-vision stays awake for it
  /// (`vision.busy_wait_ms`: its decode workers poll); zero: it always sleeps until a message
  /// comes.
  explicit FrameCadence(std::chrono::microseconds awake) : awake_(awake) {}

  /// A pair came at `t` (its second image's handler began).
  void arrived(Clock::time_point t);

  /// How long the caller may sleep at `now` waiting for a message, at most `longest`: 0 inside
  /// the window around the next pair's due time.
  std::chrono::microseconds sleep_before_next(Clock::time_point now,
                                              std::chrono::microseconds longest) const;

  /// The period learned, the median interval (zero before three intervals are known).
  std::chrono::microseconds period() const { return period_; }

 private:
  static constexpr size_t kIntervals = 15;
  static constexpr int kPeriodsWithoutPair = 10;
  std::chrono::microseconds awake_;
  std::array<std::chrono::microseconds, kIntervals> intervals_{};
  size_t count_ = 0;  // intervals seen, all of them
  Clock::time_point last_{};
  bool any_ = false;
  std::chrono::microseconds period_{0};                 // the median interval
  std::chrono::microseconds shortest_{0}, longest_{0};  // the ordinary intervals' spread
};

}  // namespace sg::vision
