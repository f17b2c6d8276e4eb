// Pairing left and right frames by capture time.

#include "vision/stereo_pairer.hpp"

#include <gtest/gtest.h>

namespace sg::vision {
namespace {

// Frames within the tolerance pair in either arrival order; a frame whose partner never comes is
// counted once the other side has moved past it.
TEST(StereoPairer, PairsByUtimeAndCountsOrphans) {
  StereoPairer<int> pairer(5000);
  EXPECT_FALSE(pairer.add(0, 1'000'000, 1));
  auto pair = pairer.add(1, 1'003'000, 2);  // 3 ms later: a pair
  ASSERT_TRUE(pair);
  EXPECT_EQ(pair->first, 1);
  EXPECT_EQ(pair->second, 2);
  EXPECT_FALSE(pairer.add(1, 2'000'000, 4));  // right first this time
  pair = pairer.add(0, 2'000'000, 3);
  ASSERT_TRUE(pair);
  EXPECT_EQ(pair->first, 3) << "left stays first";
  EXPECT_EQ(pair->second, 4);
  EXPECT_EQ(pairer.unmatched(), 0u);

  EXPECT_FALSE(pairer.add(0, 3'000'000, 5));  // its right frame is lost
  EXPECT_FALSE(pairer.add(1, 3'100'000, 6));  // 100 ms later: not its partner; 5 is an orphan
  EXPECT_EQ(pairer.unmatched(), 1u);
  pair = pairer.add(0, 3'101'000, 7);
  ASSERT_TRUE(pair);
  EXPECT_EQ(pair->second, 6);
  EXPECT_FALSE(pairer.add(0, 4'000'000, 8));
  EXPECT_FALSE(pairer.add(0, 4'033'000, 9));  // replaces 8 before any right frame came
  EXPECT_EQ(pairer.unmatched(), 2u);
}

}  // namespace
}  // namespace sg::vision
