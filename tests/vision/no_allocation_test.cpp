// Tracking allocates no memory per frame once running (issue 4), and the shipped configuration
// is the tracker's defaults.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <opencv2/imgproc.hpp>

#include "tests/support/allocation_counter.hpp"
#include "vision/blob_tracker.hpp"
#include "vision/vision_config.hpp"

namespace sg::vision {
namespace {

// After the first frames, tracking the ball frame after frame allocates nothing.
TEST(Tracking, NoAllocationPerFrame) {
  std::vector<cv::Mat> frames;
  for (int k = 0; k < 20; ++k) {
    cv::Mat image(480, 640, CV_8UC3, cv::Scalar(120, 125, 130));
    cv::circle(image, {200 + 5 * k, 240 - 2 * k}, 22, cv::Scalar(30, 35, 200), cv::FILLED);
    frames.push_back(image);
  }
  BlobTracker tracker({}, {640, 480});
  for (int k = 0; k < 3; ++k) tracker.track(frames[static_cast<size_t>(k)]);  // warm up
  const long before = sg::test::allocations();
  int found = 0;
  for (size_t k = 3; k < frames.size(); ++k) found += tracker.track(frames[k]).found;
  EXPECT_EQ(sg::test::allocations() - before, 0);
  EXPECT_EQ(found, 17);
  cv::Mat copy = frames[0].clone();  // the counter does count: OpenCV allocates here
  EXPECT_GT(sg::test::allocations() - before, 0);
}

// config/stereograsp.yaml's vision section is the tracker's defaults; a bad value names its key.
TEST(VisionConfig, ShippedDefaultsAndErrors) {
  const auto shipped =
      load_tracker_params(Config::load(std::string(SG_SOURCE_DIR) + "/config/stereograsp.yaml"));
  const BlobTracker::Params defaults;
  EXPECT_DOUBLE_EQ(shipped.color.r_min, defaults.color.r_min);
  EXPECT_DOUBLE_EQ(shipped.color.g_max, defaults.color.g_max);
  EXPECT_DOUBLE_EQ(shipped.color.b_max, defaults.color.b_max);
  EXPECT_EQ(shipped.color.min_intensity, defaults.color.min_intensity);
  EXPECT_EQ(shipped.min_area, defaults.min_area);
  EXPECT_DOUBLE_EQ(shipped.window.max_width_fraction, 0.24);
  EXPECT_DOUBLE_EQ(shipped.window.max_height_fraction, 0.32);
  EXPECT_EQ(shipped.window.misses_before_full_frame, defaults.window.misses_before_full_frame);
  try {
    load_tracker_params(Config::parse("vision:\n  g_range: [0.4, 0.2]\n", "lab.yaml"));
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("lab.yaml:2:12: key 'vision.g_range'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace sg::vision
