// When sg-vision stays awake for the next stereo pair (issue 19): the period from the pairs'
// intervals, the window around each due time, and sleeping again when the cameras stop.

#include "vision/frame_cadence.hpp"

#include <gtest/gtest.h>

namespace sg::vision {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::seconds;
const FrameCadence::Clock::time_point t0{std::chrono::seconds(1000)};

/// A cadence that saw `n` pairs `period` apart, the last at t0.
FrameCadence after_pairs(int n, microseconds period, microseconds awake = microseconds(1500)) {
  FrameCadence c(awake);
  for (int i = n - 1; i >= 0; --i) c.arrived(t0 - period * i);
  return c;
}

// Before three intervals are known the thread sleeps as long as it is allowed.
TEST(FrameCadence, SleepsUntilThreeIntervalsAreKnown) {
  const FrameCadence c = after_pairs(3, milliseconds(50));
  EXPECT_EQ(c.period(), microseconds(0));
  EXPECT_EQ(c.sleep_before_next(t0 + milliseconds(49), milliseconds(100)), milliseconds(100));
  EXPECT_EQ(after_pairs(4, milliseconds(50)).period(), milliseconds(50));
}

// At 20 Hz with 1.5 ms awake: sleep until 48.5 ms after the last pair, then poll until 51.5 ms.
TEST(FrameCadence, AwakeAroundTheDueTime) {
  const FrameCadence c = after_pairs(10, milliseconds(50));
  EXPECT_EQ(c.sleep_before_next(t0, milliseconds(100)), microseconds(48500));
  EXPECT_EQ(c.sleep_before_next(t0 + milliseconds(40), milliseconds(5)), milliseconds(5));
  EXPECT_EQ(c.sleep_before_next(t0 + milliseconds(48), milliseconds(100)), microseconds(500));
  EXPECT_EQ(c.sleep_before_next(t0 + microseconds(48500), milliseconds(100)), microseconds(0));
  EXPECT_EQ(c.sleep_before_next(t0 + microseconds(51500), milliseconds(100)), microseconds(0));
  // Past the window: the next frame's (a dropped one is no reason to stay awake).
  EXPECT_EQ(c.sleep_before_next(t0 + microseconds(51501), milliseconds(100)),
            microseconds(98500 - 51501));
}

// Frames that come 48 or 52 ms apart keep the thread awake from 47 to 53 ms after the last pair
// (1 ms either side), then from a period (the median, 48 ms) later for the one after.
TEST(FrameCadence, JitterWidensTheWindow) {
  FrameCadence c(microseconds(1000));
  auto t = t0;
  for (int i = 0; i < 10; ++i) c.arrived(t += milliseconds(i % 2 ? 48 : 52));
  EXPECT_EQ(c.period(), milliseconds(48));  // the median of 5 x 48 and 4 x 52
  EXPECT_EQ(c.sleep_before_next(t, seconds(1)), milliseconds(47));
  EXPECT_EQ(c.sleep_before_next(t + milliseconds(47), seconds(1)), microseconds(0));
  EXPECT_EQ(c.sleep_before_next(t + milliseconds(53), seconds(1)), microseconds(0));
  EXPECT_EQ(c.sleep_before_next(t + microseconds(53001), seconds(1)),
            microseconds(47000 + c.period().count() - 53001));
}

// The period is the median interval: a stall and a burst after it do not move it.
TEST(FrameCadence, PeriodIsTheMedianInterval) {
  FrameCadence c(microseconds(1000));
  auto t = t0;
  for (int i = 0; i < 12; ++i) c.arrived(t += milliseconds(250));
  c.arrived(t += milliseconds(900));  // a stall
  c.arrived(t += milliseconds(1));    // and the frames it held up
  c.arrived(t += milliseconds(1));
  EXPECT_EQ(c.period(), milliseconds(250));
  EXPECT_EQ(c.sleep_before_next(t, seconds(1)), milliseconds(249));  // nor widen the window
}

// Ten periods without a pair: the cameras stopped, and the thread sleeps until one comes.
TEST(FrameCadence, SleepsWhenTheCamerasStop) {
  const FrameCadence c = after_pairs(10, milliseconds(50));
  EXPECT_EQ(c.sleep_before_next(t0 + milliseconds(499), milliseconds(100)), microseconds(0));
  EXPECT_EQ(c.sleep_before_next(t0 + milliseconds(520), milliseconds(100)), milliseconds(100));
}

// With no time awake (vision.busy_wait_ms: 0) the thread always sleeps until a message comes.
TEST(FrameCadence, ZeroAwakeNeverPolls) {
  const FrameCadence c = after_pairs(10, milliseconds(50), microseconds(0));
  EXPECT_EQ(c.sleep_before_next(t0 + milliseconds(50), milliseconds(100)), milliseconds(100));
}

}  // namespace
}  // namespace sg::vision
