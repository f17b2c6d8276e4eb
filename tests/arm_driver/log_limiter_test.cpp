// LogLimiter: the first ten lines of a kind pass, then one a second with the count held back.

#include "arm_driver/log_limiter.hpp"

#include <gtest/gtest.h>

namespace sg::arm {
namespace {

// 1000 lines in 0.999 s: the first 10 logged; at t = 1.5 s one more, telling of 990 held back.
TEST(LogLimiter, TenThenOneASecondWithTheCountHeldBack) {
  LogLimiter limit;
  int logged = 0;
  uint64_t held_back = 99;
  for (int i = 0; i < 1000; ++i) logged += limit.allow("lease", 0.001 * i, held_back);
  EXPECT_EQ(logged, 10);
  EXPECT_EQ(held_back, 0u);  // the tenth line had nothing held back before it
  EXPECT_TRUE(limit.allow("lease", 1.5, held_back));
  EXPECT_EQ(held_back, 990u);
  EXPECT_FALSE(limit.allow("lease", 2.0, held_back));
  EXPECT_TRUE(limit.allow("lease", 2.5, held_back));
  EXPECT_EQ(held_back, 1u);
}

// Kinds are counted apart: a flood of one leaves the first lines of another logged.
TEST(LogLimiter, KindsAreCountedApart) {
  LogLimiter limit(2, 1.0);
  uint64_t held_back = 0;
  for (int i = 0; i < 5; ++i) limit.allow("rejected", 0.0, held_back);
  EXPECT_TRUE(limit.allow("unauthenticated", 0.0, held_back));
  EXPECT_EQ(held_back, 0u);
}

}  // namespace
}  // namespace sg::arm
