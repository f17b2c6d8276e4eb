// The real-scene generator: deterministic, and its truth is what it draws.

#include "sim/real_scene.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/imgproc.hpp>

namespace sg::sim {
namespace {

bool have_data() { return std::filesystem::exists(opencv_data_dir() + "/home.jpg"); }

// The same parameters give the same bytes, frame by frame.
TEST(RealScene, Deterministic) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << opencv_data_dir();
  RealScene a(standard_real_scenes(100)[0]), b(standard_real_scenes(100)[0]);
  cv::Mat x, y;
  RealSceneTruth tx, ty;
  for (int k : {0, 1, 57}) {
    a.render(k, x, tx);
    b.render(k, y, ty);
    EXPECT_EQ(cv::norm(x, y, cv::NORM_INF), 0) << k;
    EXPECT_EQ(tx.centre, ty.centre);
  }
}

// Without noise, lighting or JPEG, the pixels the ball changes (against a frame without it) have
// their centroid at the true centre within 0.1 px and cover the disc and at most a pixel's rim;
// the panel's sweep and the out-of-view segment show in the visible share.
TEST(RealScene, TruthIsWhatIsDrawn) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << opencv_data_dir();
  RealSceneParams p = standard_real_scenes(720)[0];
  p.lighting = false, p.noise_sigma = 0, p.jpeg_quality = 0;
  RealScene with(p);
  cv::Mat img, ref;
  RealSceneTruth t;
  with.render(10, img, t);
  ASSERT_EQ(t.visible, 1.0);
  // The ball's albedo is mostly red: its coverage shows in the red channel's change from the
  // background, which frame 650 (ball out of view) gives unchanged.
  with.render(650, ref, t);
  with.render(10, img, t);
  cv::Mat diff;
  cv::absdiff(img, ref, diff);
  cv::Mat any;
  cv::cvtColor(diff, any, cv::COLOR_BGR2GRAY);
  const cv::Moments m = cv::moments(any > 0, true);
  EXPECT_NEAR(m.m10 / m.m00, t.centre.x, 0.1);
  EXPECT_NEAR(m.m01 / m.m00, t.centre.y, 0.1);
  // Every pixel the disc touches changes: those whose centres lie within about r + 0.7 px.
  EXPECT_GT(m.m00, M_PI * t.radius * t.radius);
  EXPECT_LT(m.m00, M_PI * (t.radius + 1) * (t.radius + 1));
  with.render(330, img, t);  // the panel half-way over the ball
  EXPECT_GT(t.visible, 0.2);
  EXPECT_LT(t.visible, 0.8);
  with.render(400, img, t);  // behind the panel
  EXPECT_EQ(t.visible, 0.0);
  EXPECT_TRUE(t.in_view);
  with.render(650, img, t);
  EXPECT_FALSE(t.in_view);
}

// A missing data folder is a clear error naming the package.
TEST(RealScene, MissingDataSaysWhatToInstall) {
  setenv("SG_OPENCV_DATA", "/nonexistent-opencv-data", 1);
  try {
    RealScene s(standard_real_scenes(10)[0]);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("apt-get install opencv-doc"), std::string::npos);
  }
  unsetenv("SG_OPENCV_DATA");
}

}  // namespace
}  // namespace sg::sim
