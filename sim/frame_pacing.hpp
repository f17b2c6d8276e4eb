#pragma once

#include <algorithm>
#include <cstdint>

namespace sg::sim {

/// Which frame a real-time camera delivers next. A camera captures frame k at
/// t_k = start + k * period and never falls behind the clock: a frame nobody could take in time is
/// dropped, and the next one captured is the newest that has begun. sg-camera-sim does the same
/// when rendering cannot keep its rate (a loaded or sanitized machine): frame `next` is rendered
/// while the clock is at most `max_lag_us` past t_next; beyond that it skips to
///
///     k = floor(elapsed / period),
///
/// so a frame's capture time (its utime) is never more than max_lag + one period older than the
/// moment it is published. `max_lag_us` <= 0 never skips: every frame is rendered, however late
/// (a run that must show every frame of its timeline, e.g. a test counting frames).
///
///     sg::sim::FramePacing pacing(period_us, max_lag_us);
///     k = pacing.next_frame(k, elapsed_us, frames);  // elapsed: now - start, after sleeping
///     if (k == frames) break;                           //   until t_k; the run is over
///     pacing.skipped();                                 // frames dropped so far
class FramePacing {
 public:
  FramePacing(int64_t period_us, int64_t max_lag_us)
      : period_us_(period_us), max_lag_us_(max_lag_us) {}

  /// The frame to render when `next` is due and `elapsed_us` have passed since the start;
  /// counts the frames it skips. A run of `end` frames (0: endless) skips at most to `end`, the
  /// frame after its last: what lies beyond the run is not counted.
  int64_t next_frame(int64_t next, int64_t elapsed_us, int64_t end = 0) {
    if (max_lag_us_ <= 0 || period_us_ <= 0 || elapsed_us - next * period_us_ <= max_lag_us_)
      return next;
    int64_t newest = elapsed_us / period_us_;
    if (end > 0) newest = std::min(newest, end);
    if (newest <= next) return next;
    skipped_ += newest - next;
    return newest;
  }

  /// Frames skipped so far.
  int64_t skipped() const { return skipped_; }

 private:
  int64_t period_us_;
  int64_t max_lag_us_;
  int64_t skipped_ = 0;
};

}  // namespace sg::sim
