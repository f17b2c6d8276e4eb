// sg-c550-sim's ball between GROUND_TRUTH frames: extrapolated linearly from the last two, held
// when there is one, when they are far apart or out of order, and cleared by an unknown ball.

#include "sim/ball_track.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sg::sim {
namespace {

constexpr int64_t kFrame = 250'000;  // 4 Hz

TEST(BallTrack, UnknownBeforeAnySample) { EXPECT_FALSE(BallTrack().at(0).has_value()); }

TEST(BallTrack, OneSampleIsHeld) {
  BallTrack track;
  track.add(1'000'000, {0.4, 0.1, 0.1});
  EXPECT_TRUE(track.at(1'200'000)->isApprox(Eigen::Vector3d(0.4, 0.1, 0.1)));
}

// A ball moving 31 mm/s along Y, asked for 0.2 s after its last frame: 6.2 mm on, not where the
// frame left it.
TEST(BallTrack, ExtrapolatesTheLastTwoFrames) {
  BallTrack track;
  track.add(1'000'000, {0.45, 0.0, 0.1});
  track.add(1'000'000 + kFrame, {0.45, 0.031 * 0.25, 0.1});
  const Eigen::Vector3d at = *track.at(1'000'000 + kFrame + 200'000);
  EXPECT_NEAR(at.y(), 0.031 * 0.45, 1e-9);
  EXPECT_NEAR(at.x(), 0.45, 1e-12);
}

// On the paper's circle (0.15 m, 2 rpm) the linear extrapolation over a 4 Hz frame is within
// half a millimetre of the truth, where holding the last frame is up to 8 mm off.
TEST(BallTrack, WithinHalfAMillimetreOnTheCircleAtFourHertz) {
  const double omega = 2 * M_PI * 2 / 60, r = 0.15;
  auto ball = [&](double t) {
    return Eigen::Vector3d(0.45 + r * std::cos(omega * t), r * std::sin(omega * t), 0.1);
  };
  BallTrack track;
  double worst = 0, held_worst = 0;
  for (int k = 0; k < 240; ++k) {
    const double t = 0.25 * k;
    track.add(static_cast<int64_t>(t * 1e6), ball(t));
    if (k == 0) continue;
    for (double dt = 0; dt < 0.25; dt += 0.01) {
      const double now = t + dt;
      worst = std::max(worst, (*track.at(static_cast<int64_t>(now * 1e6)) - ball(now)).norm());
      held_worst = std::max(held_worst, (ball(t) - ball(now)).norm());
    }
  }
  EXPECT_LT(worst, 0.0005);
  EXPECT_GT(held_worst, 0.007);
}

TEST(BallTrack, ExtrapolatesAtMostHalfASecond) {
  BallTrack track;
  track.add(0, {0, 0, 0});
  track.add(kFrame, {0.01, 0, 0});
  EXPECT_NEAR(track.at(10'000'000)->x(), 0.01 + 0.04 * 0.5, 1e-12);
}

TEST(BallTrack, HoldsWhenTheFramesAreFarApartOrOutOfOrder) {
  BallTrack track;
  track.add(0, {0, 0, 0});
  track.add(2'000'000, {0.1, 0, 0});
  EXPECT_DOUBLE_EQ(track.at(2'100'000)->x(), 0.1);
  track.add(1'900'000, {0.2, 0, 0});
  EXPECT_DOUBLE_EQ(track.at(2'100'000)->x(), 0.2);
}

TEST(BallTrack, AnUnknownBallClearsIt) {
  BallTrack track;
  track.add(0, {0, 0, 0});
  track.add(kFrame, {NAN, 0, 0});
  EXPECT_FALSE(track.at(kFrame).has_value());
}

// Hostile GROUND_TRUTH: times at the int64 limits and centres near 1e308 neither overflow nor
// give a non-finite centre; a time far before the newest frame extrapolates back at most 0.5 s.
TEST(BallTrack, HostileTimesAndCentresStayFinite) {
  constexpr int64_t kMin = std::numeric_limits<int64_t>::min();
  constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
  BallTrack track;
  track.add(kMin, Eigen::Vector3d(0, 0, 0));
  track.add(kMax, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(*track.at(0), Eigen::Vector3d(1, 0, 0)) << "frames too far apart: held";
  EXPECT_EQ(*track.at(kMin), Eigen::Vector3d(1, 0, 0));
  track.add(0, Eigen::Vector3d(1e308, 0, 0));
  track.add(250'000, Eigen::Vector3d(-1e308, 0, 0));
  EXPECT_EQ(*track.at(500'000), Eigen::Vector3d(-1e308, 0, 0)) << "overflowed: the newest";
  BallTrack back;
  back.add(1'000'000, Eigen::Vector3d(0, 0, 0));
  back.add(1'250'000, Eigen::Vector3d(0.25, 0, 0));  // 1 m/s
  EXPECT_NEAR(back.at(kMin)->x(), 0.25 - 0.5, 1e-12);
}

}  // namespace
}  // namespace sg::sim
