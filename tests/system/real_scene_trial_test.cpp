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

/// Scene `i` of standard_real_scenes(720) — one whole cycle: visible, behind the panel, between
/// the fingers, out of view — with the scored selection, run once per test program (ctest runs
/// the program whole: tests/system/CMakeLists.txt).
const RealSceneFigures& scored(size_t i) {
  static std::map<size_t, RealSceneFigures> runs;
  if (!runs.count(i))
    runs[i] = run_real_scene(sim::standard_real_scenes(720)[i], vision::Selection::kScored);
  return runs[i];
}

bool have_data() {
  return std::filesystem::exists(sim::opencv_data_dir() + "/home.jpg") &&
         std::filesystem::exists(sim::opencv_data_dir() + "/vtest.avi");
}

// home.jpg (houses, sky) with a cloth 25 times the ball's area, one cycle: the ball within 2 px of
// its true centre in 99% of the fully visible frames, never on another object, no detection while
// it is hidden (222 hidden frames).
TEST(RealSceneTrial, HousesWithARedClothScored) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  const RealSceneFigures& f = scored(0);
  ASSERT_GT(f.visible, 300);
  EXPECT_GE(f.within_2px_share(), 0.99);
  EXPECT_EQ(f.visible_elsewhere, 0);
  ASSERT_GT(f.hidden, 200);
  EXPECT_EQ(f.hidden_false, 0);
}

// fruits.jpg: the ball passes an orange and red cabbage whose rims lie inside the default colour
// ranges; with the ranges narrowed to the ball's (vision/color_adaptation.hpp) it is found within
// 2 px in 99% of the fully visible frames, never on a fruit, never while hidden.
TEST(RealSceneTrial, FruitsScored) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  const RealSceneFigures& f = scored(1);
  EXPECT_GE(f.within_2px_share(), 0.99);
  EXPECT_EQ(f.visible_elsewhere, 0);
  EXPECT_EQ(f.hidden_false, 0);
}

// The half-hidden ball (40-60% of its disc visible, behind the panel or between the fingers) in
// all three scenes: found in most such frames (a ball coming out from behind the panel is taken
// up again once half its outline shows), its centre within 1.5 px at p95, where the centroid of
// eq. 11 is off by a third of the radius.
TEST(RealSceneTrial, HalfHiddenBallsCentre) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  RealSceneFigures f = scored(0);
  f.add(scored(1));
  f.add(scored(2));
  ASSERT_GE(f.half_hidden, 50);
  ASSERT_GE(f.half_centre_error.size(), static_cast<size_t>(f.half_hidden * 2 / 3));
  EXPECT_LE(quantile(f.half_centre_error, 0.95), 1.5);
  EXPECT_GT(quantile(f.half_centroid_error, 0.5), 5.0);
  std::printf(
      "half hidden: %zu of %d frames found, centre p50 %.2f p95 %.2f px, centroid p50 %.2f px\n",
      f.half_centre_error.size(), f.half_hidden, quantile(f.half_centre_error, 0.5),
      quantile(f.half_centre_error, 0.95), quantile(f.half_centroid_error, 0.5));
}

// People walking (vtest.avi) behind the ball, one in a maroon jacket, with the cloth: 99% within
// 2 px, never on another object, no detection while the ball is hidden.
TEST(RealSceneTrial, WalkingPeopleScored) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  const RealSceneFigures& f = scored(2);
  EXPECT_GE(f.within_2px_share(), 0.99);
  EXPECT_EQ(f.visible_elsewhere, 0);
  EXPECT_EQ(f.hidden_false, 0);
}

// The fruits without colour adaptation: the ball merges with the orange's rim inside the default
// ranges, and fewer than 95% of the fully visible frames are within 2 px.
TEST(RealSceneTrial, FruitsWithoutColourAdaptation) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  const RealSceneFigures f =
      run_real_scene(sim::standard_real_scenes(720)[1], vision::Selection::kScored, false);
  EXPECT_LT(f.within_2px_share(), 0.95);
}

// The paper's rule on the same scene's first 240 frames (the ball in full view): the cloth is the
// largest red region, so it is taken for the ball in nearly every frame.
TEST(RealSceneTrial, LargestRegionRuleTakesTheCloth) {
  if (!have_data()) GTEST_SKIP() << "no opencv-doc data in " << sim::opencv_data_dir();
  sim::RealSceneParams scene = sim::standard_real_scenes(240)[0];
  const RealSceneFigures f = run_real_scene(scene, vision::Selection::kLargest);
  EXPECT_LT(f.within_2px_share(), 0.2);
  EXPECT_GT(f.visible_elsewhere, f.visible / 2);
}

}  // namespace
}  // namespace sg::system
