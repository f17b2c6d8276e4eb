// Which region is the ball (issue 16): the segmenter's candidates, the score (ball_score.hpp),
// the learned colour and background, and the stereo pairing (stereo_match.hpp), each against a
// scene whose answer is known by construction.

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "vision/ball_score.hpp"
#include "vision/blob_tracker.hpp"
#include "vision/color_model.hpp"
#include "vision/segmentation.hpp"
#include "vision/stereo_match.hpp"
#include "vision/stereo_step.hpp"

namespace sg::vision {
namespace {

const cv::Scalar kRed(30, 35, 200), kGrey(120, 125, 130);

cv::Mat grey_image() { return cv::Mat(480, 640, CV_8UC3, kGrey); }

/// Two cameras 0.5 m apart, 1 m from the middle of the workspace.
StereoCalibration rig() {
  StereoCalibration c;
  c.left = CameraModel::look_at(640, 480, {}, {}, {-0.25, -1.0, 0.3}, {0, 0, 0});
  c.right = CameraModel::look_at(640, 480, {}, {}, {0.25, -1.0, 0.3}, {0, 0, 0});
  return c;
}

/// A red disc where a sphere of `radius` m at `world` images in `camera`.
void draw_sphere(cv::Mat& image, const CameraModel& camera, const Eigen::Vector3d& world,
                 double radius, const cv::Scalar& colour = kRed) {
  const Eigen::Vector2d px = *camera.project(world);
  const double r = apparent_radius(camera, world, radius);
  cv::circle(image, cv::Point(cvRound(px.x() * 256), cvRound(px.y() * 256)), cvRound(r * 256),
             colour, cv::FILLED, cv::LINE_AA, 8);
}

cv::Point2d pixel(const CameraModel& camera, const Eigen::Vector3d& world) {
  const Eigen::Vector2d p = *camera.project(world);
  return {p.x(), p.y()};
}

// The segmenter keeps the largest regions largest first, with their extent, colour and mask.
TEST(Segmenter, CandidatesLargestFirstWithBoxColourAndMask) {
  cv::Mat image = grey_image();
  cv::rectangle(image, cv::Rect(10, 20, 30, 10), kRed, cv::FILLED);    // 300 px
  cv::rectangle(image, cv::Rect(100, 100, 20, 20), kRed, cv::FILLED);  // 400 px
  cv::rectangle(image, cv::Rect(300, 300, 5, 5), kRed, cv::FILLED);    // 25 px, under min_area
  Segmenter segmenter(image.size());
  const Segmentation s = segmenter.run(image, {0, 0, 640, 480}, ColorDetector({}), 30);
  EXPECT_EQ(s.num_regions, 3);
  ASSERT_EQ(s.num_candidates, 2);
  EXPECT_EQ(s.regions[0].moments.m00, 400);
  EXPECT_EQ(s.regions[0].box(), cv::Rect(100, 100, 20, 20));
  EXPECT_EQ(s.regions[1].box(), cv::Rect(10, 20, 30, 10));
  EXPECT_NEAR(s.regions[0].mean_r(), 200.0 / 265, 1e-12);
  EXPECT_NEAR(s.regions[0].mean_g(), 35.0 / 265, 1e-12);
  const cv::Mat mask = segmenter.mask_of(s.regions[1]);
  EXPECT_EQ(segmenter.mask_origin(), cv::Point(9, 19));
  EXPECT_EQ(mask.size(), cv::Size(32, 12));
  EXPECT_EQ(cv::countNonZero(mask), 300);
  EXPECT_EQ(mask.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(mask.at<uint8_t>(1, 1), 255);
}

// More regions than it keeps: the kept ones are the largest, in order.
TEST(Segmenter, KeepsTheLargestOfManyRegions) {
  cv::Mat image = grey_image();
  for (int i = 0; i < 12; ++i) {
    cv::rectangle(image, cv::Rect(20 + 50 * i, 200, 6 + (i * 7) % 12, 30), kRed, cv::FILLED);
  }
  Segmenter segmenter(image.size());
  const Segmentation s = segmenter.run(image, {0, 0, 640, 480}, ColorDetector({}), 1);
  ASSERT_EQ(s.num_candidates, Segmentation::kMaxRegions);
  for (int k = 1; k < s.num_candidates; ++k) {
    EXPECT_GE(s.regions[static_cast<size_t>(k - 1)].moments.m00,
              s.regions[static_cast<size_t>(k)].moments.m00);
  }
  EXPECT_EQ(s.regions[0].moments.m00, 17 * 30);
  EXPECT_EQ(s.largest.m00, 17 * 30);
}

// A ball beside a larger red rectangle: the paper's rule takes the rectangle, the score the ball.
TEST(BallSelection, RoundBallBeatsALargerRedRectangle) {
  cv::Mat image = grey_image();
  cv::circle(image, {200, 240}, 20, kRed, cv::FILLED, cv::LINE_AA);
  cv::rectangle(image, cv::Rect(380, 150, 160, 120), kRed, cv::FILLED);
  BlobTracker::Params largest;
  largest.selection = Selection::kLargest;
  const Observation a = BlobTracker(largest, image.size()).track(image);
  ASSERT_TRUE(a.found);
  EXPECT_GT(a.centre.x, 380);
  const Observation b = BlobTracker({}, image.size()).track(image);
  ASSERT_TRUE(b.found);
  EXPECT_LT(cv::norm(b.centre - cv::Point2d(200, 240)), 0.5);
  EXPECT_EQ(b.candidates, 2);
  EXPECT_GT(b.confidence, 0.5);
}

// Half the ball hidden behind a grey panel: the centroid is the half disc's, the centre the ball's.
TEST(BallSelection, HalfHiddenBallCentreIsFitted) {
  cv::Mat image = grey_image();
  cv::circle(image, {320, 240}, 25, kRed, cv::FILLED);
  image(cv::Rect(320, 0, 320, 480)) = kGrey;
  const Observation o = BlobTracker({}, image.size()).track(image);
  ASSERT_TRUE(o.found);
  EXPECT_NEAR(o.blob.centroid.x, 320 - 4 * 25 / (3 * M_PI) - 0.5, 0.6);  // half-disc centroid
  EXPECT_LT(cv::norm(o.centre - cv::Point2d(320, 240)), 1.5);
  EXPECT_NEAR(o.radius, 25.5, 1.5);
  EXPECT_NEAR(o.fit_support, 0.5, 0.1);
}

// The colour model follows the mean of what it is given and ignores what is not a number.
TEST(ColorModel, LearnsMeanAndSpreadAndIgnoresNaN) {
  ColorModel m;
  EXPECT_FALSE(m.estimate());
  for (int k = 0; k < 200; ++k) m.add(k % 2 ? 0.72 : 0.68, 0.12);
  m.add(std::nan(""), 0.5);
  ASSERT_TRUE(m.estimate());
  const cv::Vec4d e = *m.estimate();
  EXPECT_NEAR(e[0], 0.70, 0.002);
  EXPECT_NEAR(e[1], 0.02, 0.002);  // the spread of 0.68 / 0.72
  EXPECT_NEAR(e[2], 0.12, 1e-9);
  EXPECT_DOUBLE_EQ(e[3], 0.01);  // the floor
  EXPECT_EQ(m.samples(), 200);
}

// A red region that stays put while the ball moves is learned as background and then costs more.
TEST(BallSelection, StaticRegionIsLearnedAsClutter) {
  BlobTracker::Params p;
  p.clutter_frames = 10;
  p.window.misses_before_full_frame = 0;  // every frame searched whole, so the sticker is seen
  BlobTracker tracker(p, {640, 480});
  Detection last;
  for (int k = 0; k < 25; ++k) {
    cv::Mat image = grey_image();
    cv::circle(image, {100 + 8 * k, 240}, 20, kRed, cv::FILLED, cv::LINE_AA);
    cv::circle(image, {560, 80}, 18, kRed, cv::FILLED, cv::LINE_AA);
    last = tracker.detect(image);
    ASSERT_GE(last.best, 0);
    EXPECT_LT(std::abs(last.candidates[static_cast<size_t>(last.best)].centre.x - (100 + 8 * k)),
              1.0)
        << k;
    tracker.accept(last, last.best);
  }
  ASSERT_EQ(last.count, 2);
  const Candidate& sticker = last.candidates[last.candidates[0].centre.x > 500 ? 0 : 1];
  EXPECT_TRUE(sticker.clutter);
}

// apparent_radius: a sphere on the optical axis at distance D images as f R / sqrt(D^2 - R^2).
TEST(StereoMatch, ApparentRadiusOnTheAxis) {
  const CameraModel cam = CameraModel::look_at(640, 480, {}, {}, {0, -1, 0}, {0, 0, 0});
  EXPECT_NEAR(apparent_radius(cam, {0, 0, 0}, 0.035), 560 * 0.035 / std::sqrt(1 - 0.035 * 0.035),
              1e-9);
  EXPECT_TRUE(std::isnan(apparent_radius(cam, {0, -2, 0}, 0.035)));  // behind
}

// A ball and a large red disc on a far wall in both images: the stereo pair that fits the ball's
// size at its depth is the ball; with only the wall's disc in view nothing is taken.
TEST(StereoMatch, SizeAtDepthRejectsAFarRedObject) {
  const StereoCalibration cal = rig();
  const Eigen::Vector3d ball(0.05, 0.02, 0.08), wall(-0.3, 2.0, 0.4);
  std::array<cv::Mat, 2> with_ball{grey_image(), grey_image()}, without{grey_image(), grey_image()};
  for (size_t i = 0; i < 2; ++i) {
    const CameraModel& cam = i == 0 ? cal.left : cal.right;
    for (cv::Mat* m : {&with_ball[i], &without[i]}) draw_sphere(*m, cam, wall, 0.25);
    draw_sphere(with_ball[i], cam, ball, 0.035);
  }
  StereoStep step({}, {640, 480}, cal, StereoMatchParams{.ball_radius = 0.035});
  const StereoOutput out = step.process(with_ball[0], with_ball[1], 1, 1000);
  ASSERT_TRUE(out.position && out.position->visible);
  EXPECT_LT((Eigen::Vector3d(out.position->position) - ball).norm(), 0.002);
  EXPECT_LT(cv::norm(out.observation[0].centre - pixel(cal.left, ball)), 0.5);
  StereoStep fresh({}, {640, 480}, cal, StereoMatchParams{.ball_radius = 0.035});
  const StereoOutput none = fresh.process(without[0], without[1], 1, 1000);
  EXPECT_FALSE(none.observation[0].found);
  EXPECT_FALSE(none.observation[1].found);
  EXPECT_FALSE(none.position->visible);
  StereoStep sizeless({}, {640, 480}, cal, StereoMatchParams{.ball_radius = 0});
  EXPECT_TRUE(sizeless.process(without[0], without[1], 1, 1000).position->visible)
      << "without the ball's size the wall's disc is a consistent pair";
}

// Two balls of the right size: the pair on corresponding epipolar lines is chosen, and a right
// candidate off the epipolar line is never paired.
TEST(StereoMatch, EpipolarGeometryPairsTheRightCandidates) {
  const StereoCalibration cal = rig();
  const Eigen::Vector3d ball(0.0, 0.0, 0.05);
  cv::Mat left = grey_image(), right = grey_image();
  draw_sphere(left, cal.left, ball, 0.035);
  const cv::Point2d r = pixel(cal.right, ball);
  cv::circle(right, cv::Point(cvRound(r.x), cvRound(r.y) + 60),
             cvRound(apparent_radius(cal.right, ball, 0.035)), kRed, cv::FILLED, cv::LINE_AA);
  StereoStep step({}, {640, 480}, cal, StereoMatchParams{.ball_radius = 0.035});
  const StereoOutput off = step.process(left, right, 1, 1000);
  EXPECT_FALSE(off.position->visible) << "60 px off the epipolar line";
  draw_sphere(right, cal.right, ball, 0.035);
  StereoStep again({}, {640, 480}, cal, StereoMatchParams{.ball_radius = 0.035});
  const StereoOutput on = again.process(left, right, 2, 2000);
  ASSERT_TRUE(on.position->visible);
  EXPECT_LT(cv::norm(on.observation[1].centre - r), 0.5);
}

}  // namespace
}  // namespace sg::vision
