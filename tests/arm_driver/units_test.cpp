// The only conversions between stereograsp's metres/radians and the C550's inches/degrees: exact
// known values (1 in = 0.0254 m by definition, 180 deg = pi rad) and round trips.

#include "arm_driver/units.hpp"

#include <gtest/gtest.h>

#include <numbers>

namespace sg::arm {
namespace {

constexpr double kPi = std::numbers::pi;

// The inch is 0.0254 m exactly, and the conversions are usable at compile time.
TEST(Units, InchIsExactly0254Metre) {
  EXPECT_EQ(kMetresPerInch, 0.0254);
  EXPECT_EQ(to_inches(0.0254), 1.0);  // x / x is exactly 1
  EXPECT_EQ(from_inches(1.0), 0.0254);
  EXPECT_EQ(from_inches(0.0), 0.0);
  EXPECT_EQ(to_inches(0.0), 0.0);
  static_assert(to_inches(0.0254) == 1.0);
  static_assert(from_inches(1.0) == 0.0254);
}

// Known lengths: 12 in = 1 ft = 0.3048 m, 100 in = 2.54 m, 1 m = 1 / 0.0254 = 39.3700787... in.
TEST(Units, KnownLengths) {
  EXPECT_DOUBLE_EQ(from_inches(12.0), 0.3048);
  EXPECT_DOUBLE_EQ(to_inches(0.3048), 12.0);
  EXPECT_DOUBLE_EQ(from_inches(100.0), 2.54);
  EXPECT_DOUBLE_EQ(to_inches(2.54), 100.0);
  EXPECT_DOUBLE_EQ(from_inches(-0.5), -0.0127);
  EXPECT_DOUBLE_EQ(to_inches(1.0), 39.37007874015748);
  EXPECT_NEAR(to_inches(0.45), 17.7165354, 1e-7);  // 0.45 / 0.0254 = 17.71653543...
}

// 180 deg is pi and the other standard angles follow.
TEST(Units, KnownAngles) {
  EXPECT_DOUBLE_EQ(from_degrees(180.0), kPi);
  EXPECT_DOUBLE_EQ(to_degrees(kPi), 180.0);
  EXPECT_DOUBLE_EQ(from_degrees(90.0), kPi / 2);
  EXPECT_DOUBLE_EQ(from_degrees(-45.0), -kPi / 4);
  EXPECT_DOUBLE_EQ(from_degrees(360.0), 2 * kPi);
  EXPECT_DOUBLE_EQ(to_degrees(kPi / 6), 30.0);
  EXPECT_DOUBLE_EQ(to_degrees(-kPi / 3), -60.0);
  EXPECT_EQ(from_degrees(0.0), 0.0);
  EXPECT_EQ(to_degrees(0.0), 0.0);
  // 1 rad = 180 / pi = 57.295779513082320... deg; 1 deg = pi / 180 = 0.017453292519943295 rad.
  EXPECT_DOUBLE_EQ(to_degrees(1.0), 57.29577951308232);
  EXPECT_DOUBLE_EQ(from_degrees(1.0), 0.017453292519943295);
}

// Converting there and back returns the value (to a few ulps) over a wide range.
TEST(Units, RoundTrips) {
  for (double x : {-1000.0, -2.5, -0.0127, 1e-9, 0.0254, 0.45, 1.0, 3.3, 1234.5678}) {
    EXPECT_DOUBLE_EQ(from_inches(to_inches(x)), x) << x;
    EXPECT_DOUBLE_EQ(to_inches(from_inches(x)), x) << x;
    EXPECT_DOUBLE_EQ(from_degrees(to_degrees(x)), x) << x;
    EXPECT_DOUBLE_EQ(to_degrees(from_degrees(x)), x) << x;
  }
}

}  // namespace
}  // namespace sg::arm
