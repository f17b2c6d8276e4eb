// FramePacing: which frame a real-time camera delivers next, against worked timelines.

#include "sim/frame_pacing.hpp"

#include <gtest/gtest.h>

namespace sg::sim {
namespace {

// On time, or late by at most max_lag: the next frame, nothing skipped.
TEST(FramePacing, OnTimeOrSlightlyLateKeepsEveryFrame) {
  FramePacing pacing(100'000, 200'000);  // 10 Hz, 0.2 s
  EXPECT_EQ(pacing.next_frame(0, 0), 0);
  EXPECT_EQ(pacing.next_frame(1, 100'000), 1);
  EXPECT_EQ(pacing.next_frame(2, 400'000), 2);  // exactly max_lag late
  EXPECT_EQ(pacing.skipped(), 0);
}

// Late by more than max_lag: the newest frame that has begun, and the ones between counted.
TEST(FramePacing, LateBeyondMaxLagSkipsToTheNewestFrame) {
  FramePacing pacing(100'000, 200'000);
  EXPECT_EQ(pacing.next_frame(2, 450'000), 4);  // frame 2 due at 0.2 s, now 0.45 s: frames 2, 3
  EXPECT_EQ(pacing.skipped(), 2);
  EXPECT_EQ(pacing.next_frame(5, 1'250'001), 12);  // 0.75 s late: 5..11 dropped
  EXPECT_EQ(pacing.skipped(), 9);
}

// A run of 10 frames late at its frame 8 by 0.75 s skips to 10, its end: frames 8 and 9 dropped,
// none counted beyond the run.
TEST(FramePacing, SkipsNoFurtherThanTheEndOfTheRun) {
  FramePacing pacing(100'000, 200'000);
  EXPECT_EQ(pacing.next_frame(8, 1'550'000, 10), 10);
  EXPECT_EQ(pacing.skipped(), 2);
}

// max_lag 0 renders every frame, however late (a run that must show its whole timeline).
TEST(FramePacing, ZeroMaxLagNeverSkips) {
  FramePacing pacing(100'000, 0);
  EXPECT_EQ(pacing.next_frame(3, 10'000'000), 3);
  EXPECT_EQ(pacing.skipped(), 0);
}

}  // namespace
}  // namespace sg::sim
