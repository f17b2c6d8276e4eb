// The product's tracker on real photographs and video (opencv-doc) with a red cloth, a red book,
// lighting drift, noise, MJPG and occlusion (sim/real_scene.hpp): the figures where they
// hold, and the paper's largest-region rule failing on the same frames.

#include "system/real_scene_trial.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>

namespace sg::system {
namespace {

/// Scene `i` of standard_real_scenes(1440) with the scored selection, run once per test program.
const RealSceneFigures& scored(size_t i) {
  static std::map<size_t, RealSceneFigures> runs;
  if (!runs.count(i))
    runs[i] = run_real_scene(sim::standard_real_scenes(1440)[i], vision::Selection::kScored);
  return runs[i];
}

bool have_data() {
  return std::filesystem::exists(sim::opencv_data_dir() + "/home.jpg") &&
         std::filesystem::exists(sim::opencv_data_dir() + "/vtest.avi");
}

// home.jpg (houses, sky) with a cloth 25 times the ball's area, two cycles: the ball within 2 px of its true
// centre in every fully visible frame, never on another object, no detection while it is hidden
// (444 hidden frames).
TEST(RealSceneTrial, HousesWithARedClothScored) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  const RealSceneFigures& f = scored(0);
  ASSERT_GT(f.visible, 600);
  EXPECT_GE(f.within_2px_share(), 0.99);
  EXPECT_EQ(f.visible_elsewhere, 0);
  ASSERT_GT(f.hidden, 400);
  EXPECT_EQ(f.hidden_false, 0);
}

// The half-hidden ball (40-60% of its disc visible, behind the panel or between the fingers) in
// home.jpg and among the walking people: its centre within 1.5 px at p95, where the centroid
// of eq. 11 is off by a third of the radius.
TEST(RealSceneTrial, HalfHiddenBallsCentre) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  RealSceneFigures f = scored(0);
  f.add(scored(2));
  ASSERT_GE(f.half_centre_error.size(), 60u);
  EXPECT_LE(quantile(f.half_centre_error, 0.95), 1.5);
  EXPECT_GT(quantile(f.half_centroid_error, 0.5), 5.0);
  std::printf("half hidden (%zu frames): centre p50 %.2f p95 %.2f px, centroid p50 %.2f px\n",
              f.half_centre_error.size(), quantile(f.half_centre_error, 0.5),
              quantile(f.half_centre_error, 0.95), quantile(f.half_centroid_error, 0.5));
}

// People walking (vtest.avi) behind the ball, with the cloth: 98% within 2 px, never on another
// object, at most 1% of hidden frames with a detection.
TEST(RealSceneTrial, WalkingPeopleScored) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  const RealSceneFigures& f = scored(2);
  EXPECT_GE(f.within_2px_share(), 0.98);
  EXPECT_EQ(f.visible_elsewhere, 0);
  EXPECT_LE(f.hidden_false, f.hidden / 100);
}

// The paper's rule on the same scene: the cloth is the largest red region, so it is taken for
// the ball in nearly every frame.
TEST(RealSceneTrial, LargestRegionRuleTakesTheCloth) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  sim::RealSceneParams scene = sim::standard_real_scenes(720)[0];
  const RealSceneFigures f = run_real_scene(scene, vision::Selection::kLargest);
  EXPECT_LT(f.within_2px_share(), 0.2);
  EXPECT_GT(f.visible_elsewhere, f.visible / 2);
}

}  // namespace
}  // namespace sg::system
