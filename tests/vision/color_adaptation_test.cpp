// ColorAdaptation: the detector's ranges narrowed to a ball of known colour, never beyond the
// configured ones, following a drift, forgotten on request, and deaf to bad arguments.

#include "vision/color_adaptation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace sg::vision {
namespace {

/// A 200x200 grey image with a disc of `bgr` of radius 30 at (100, 100).
cv::Mat ball_image(const cv::Scalar& bgr) {
  cv::Mat image(200, 200, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::circle(image, {100, 100}, 30, bgr, cv::FILLED);
  return image;
}

double chroma(const cv::Scalar& bgr, int channel) {
  return bgr[channel] / (bgr[0] + bgr[1] + bgr[2]);
}

// A ball of one colour: each band becomes its chromaticity +- margin (0.12 wide = min_width).
TEST(ColorAdaptation, NarrowsToTheBallsChromaticity) {
  const cv::Scalar ball(26, 31, 204);  // BGR: r 0.781, g 0.119, b 0.100
  ColorAdaptation adapt(ColorThresholds{}, ColorAdaptationParams{});
  const cv::Mat image = ball_image(ball);
  for (int k = 0; k < 4; ++k) EXPECT_FALSE(adapt.learn(image, {100, 100}, 30));
  EXPECT_EQ(adapt.thresholds().r_min, ColorThresholds{}.r_min);  // not before min_samples
  EXPECT_TRUE(adapt.learn(image, {100, 100}, 30));
  const ColorThresholds& t = adapt.thresholds();
  EXPECT_NEAR(t.r_min, chroma(ball, 2) - 0.06, 1e-6);
  EXPECT_NEAR(t.r_max, chroma(ball, 2) + 0.06, 1e-6);
  EXPECT_NEAR(t.g_min, chroma(ball, 1) - 0.06, 1e-6);
  EXPECT_NEAR(t.g_max, chroma(ball, 1) + 0.06, 1e-6);
  EXPECT_NEAR(t.b_min, chroma(ball, 0) - 0.06, 1e-6);
  EXPECT_NEAR(t.b_max, chroma(ball, 0) + 0.06, 1e-6);
  // An orange inside the default ranges (r 0.648, g 0.278) is outside the learned ones.
  const uint8_t orange[3] = {20, 75, 175};
  EXPECT_TRUE(ColorDetector(ColorThresholds{}).is_object(orange));
  EXPECT_FALSE(ColorDetector(t).is_object(orange));
}

// A ball near a configured bound: the band stops at it and keeps min_width inside it.
TEST(ColorAdaptation, NeverBeyondTheConfiguredRanges) {
  ColorThresholds configured;
  configured.r_min = 0.40;
  ColorAdaptation adapt(configured, ColorAdaptationParams{});
  const cv::Scalar ball(70, 70, 100);  // r = 0.4167, g = b = 0.2917
  const cv::Mat image = ball_image(ball);
  for (int k = 0; k < 5; ++k) adapt.learn(image, {100, 100}, 30);
  const ColorThresholds& t = adapt.thresholds();
  EXPECT_DOUBLE_EQ(t.r_min, 0.40);
  EXPECT_NEAR(t.r_max, 0.52, 1e-6);   // 0.4167 + 0.06, widened to 0.12 from the bound
  EXPECT_NEAR(t.g_max, 0.30, 1e-12);  // g + margin is above the configured 0.30
  EXPECT_NEAR(t.g_min, 0.18, 1e-6);   // ... so the band is 0.12 below it
}

// The ball's colour drifts (warmer light): the ranges follow it, by rate per frame.
TEST(ColorAdaptation, FollowsADrift) {
  ColorAdaptation adapt(ColorThresholds{}, ColorAdaptationParams{});
  for (int k = 0; k < 5; ++k) adapt.learn(ball_image(cv::Scalar(26, 31, 204)), {100, 100}, 30);
  const double before = adapt.thresholds().r_min;
  const cv::Scalar warmer(40, 50, 170);  // r 0.654
  for (int k = 0; k < 60; ++k) adapt.learn(ball_image(warmer), {100, 100}, 30);
  EXPECT_NEAR(adapt.thresholds().r_min, chroma(warmer, 2) - 0.06, 1e-3);
  EXPECT_LT(adapt.thresholds().r_min, before - 0.1);
}

// forget() returns the configured ranges; the next learning starts afresh.
TEST(ColorAdaptation, ForgetReturnsTheConfiguredRanges) {
  ColorAdaptation adapt(ColorThresholds{}, ColorAdaptationParams{});
  EXPECT_FALSE(adapt.forget());
  for (int k = 0; k < 5; ++k) adapt.learn(ball_image(cv::Scalar(26, 31, 204)), {100, 100}, 30);
  EXPECT_GT(adapt.thresholds().r_min, 0.6);
  EXPECT_TRUE(adapt.forget());
  EXPECT_EQ(adapt.thresholds().r_min, ColorThresholds{}.r_min);
  EXPECT_EQ(adapt.thresholds().g_max, ColorThresholds{}.g_max);
  EXPECT_EQ(adapt.samples(), 0);
}

// Non-finite, negative, huge or off-image arguments, a wrong image type, too few pixels or
// adaptation switched off: nothing is learned.
TEST(ColorAdaptation, IgnoresBadArguments) {
  const cv::Mat image = ball_image(cv::Scalar(26, 31, 204));
  ColorAdaptation adapt(ColorThresholds{}, ColorAdaptationParams{});
  const double nan = std::nan(""), inf = INFINITY;
  for (int k = 0; k < 6; ++k) {
    EXPECT_FALSE(adapt.learn(image, {nan, 100}, 30));
    EXPECT_FALSE(adapt.learn(image, {100, inf}, 30));
    EXPECT_FALSE(adapt.learn(image, {100, 100}, nan));
    EXPECT_FALSE(adapt.learn(image, {100, 100}, -5));
    EXPECT_FALSE(adapt.learn(image, {100, 100}, 1e300));
    EXPECT_FALSE(adapt.learn(image, {-1e9, 1e9}, 30));
    EXPECT_FALSE(adapt.learn(image, {1e300, -1e300}, 30));
    EXPECT_FALSE(adapt.learn(image, {100, 100}, 2));  // 7 px: fewer than min_pixels
    EXPECT_FALSE(adapt.learn(cv::Mat(200, 200, CV_8UC1, cv::Scalar(0)), {100, 100}, 30));
  }
  EXPECT_EQ(adapt.samples(), 0);
  ColorAdaptationParams off;
  off.enabled = false;
  ColorAdaptation disabled(ColorThresholds{}, off);
  for (int k = 0; k < 6; ++k) EXPECT_FALSE(disabled.learn(image, {100, 100}, 30));
  EXPECT_EQ(disabled.thresholds().r_min, ColorThresholds{}.r_min);
}

}  // namespace
}  // namespace sg::vision
