#include "vision/frame_cadence.hpp"

#include <algorithm>

namespace sg::vision {

using std::chrono::microseconds;

void FrameCadence::arrived(Clock::time_point t) {
  if (any_) {
    intervals_[count_ % kIntervals] = std::chrono::duration_cast<microseconds>(t - last_);
    ++count_;
  }
  last_ = t;
  any_ = true;
  if (count_ < 3) return;
  const size_t n = std::min(count_, kIntervals);
  std::array<microseconds, kIntervals> sorted = intervals_;
  std::sort(sorted.begin(), sorted.begin() + static_cast<long>(n));
  period_ = sorted[n / 2];
  // The spread of the ordinary intervals: not a stall (a frame or more lost) nor the burst after.
  shortest_ = period_, longest_ = period_;
  for (size_t i = 0; i < n; ++i) {
    if (sorted[i] * 2 < period_ || sorted[i] * 2 > period_ * 3) continue;
    shortest_ = std::min(shortest_, sorted[i]);
    longest_ = std::max(longest_, sorted[i]);
  }
}

microseconds FrameCadence::sleep_before_next(Clock::time_point now, microseconds longest) const {
  if (awake_ <= microseconds(0) || period_ <= microseconds(0)) return longest;
  const microseconds elapsed = std::chrono::duration_cast<microseconds>(now - last_);
  // The first window not yet closed: the k-th frame after the last one, k >= 1.
  for (int k = 1; k <= kPeriodsWithoutPair; ++k) {
    const microseconds opens = shortest_ + period_ * (k - 1) - awake_;
    const microseconds closes = longest_ + period_ * (k - 1) + awake_;
    if (elapsed > closes) continue;
    return elapsed >= opens ? microseconds(0) : std::min(longest, opens - elapsed);
  }
  return longest;  // the cameras stopped: sleep till the next
}

}  // namespace sg::vision
