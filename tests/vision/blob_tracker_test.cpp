// Detection, segmentation and moments (sections 5.1-5.3) against analytic shapes, the window
// rules, robustness, and the simulator's frames with their known truth.

#include "vision/blob_tracker.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "sim/camera_simulator.hpp"

namespace sg::vision {
namespace {

const cv::Scalar kRed(30, 35, 200), kGrey(120, 125, 130);

BlobTracker::Params params() { return {}; }

cv::Mat grey_image() { return cv::Mat(480, 640, CV_8UC3, kGrey); }

/// A filled ellipse: every pixel whose centre lies inside it.
void fill_ellipse(cv::Mat& image, cv::Point2d c, double a, double b, double degrees) {
  const double t = degrees * M_PI / 180, ct = std::cos(t), st = std::sin(t);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const double u = (x - c.x) * ct + (y - c.y) * st, v = -(x - c.x) * st + (y - c.y) * ct;
      if (u * u / (a * a) + v * v / (b * b) <= 1) image.at<cv::Vec3b>(y, x) = {30, 35, 200};
    }
  }
}

// The moments of filled ellipses give their axes within 1% and orientation within 1 degree.
TEST(Moments, FilledEllipsesGiveTheirAxesAndOrientation) {
  for (double angle : {0.0, 30.0, 75.0, -45.0, 89.0}) {
    cv::Mat image = grey_image();
    fill_ellipse(image, {320, 240}, 90, 35, angle);
    BlobTracker::Params p = params();
    p.selection = Selection::kLargest;  // a 2.6:1 ellipse is no ball: this is about eq. 11-22
    BlobTracker tracker(p, image.size());
    const Observation o = tracker.track(image);
    ASSERT_TRUE(o.found) << angle;
    EXPECT_NEAR(o.blob.major_axis / 180.0, 1.0, 0.01) << angle;
    EXPECT_NEAR(o.blob.minor_axis / 70.0, 1.0, 0.01) << angle;
    double diff = o.blob.orientation * 180 / M_PI - angle;
    diff = std::remainder(diff, 180.0);
    EXPECT_LT(std::abs(diff), 1.0) << angle;
    EXPECT_NEAR(o.blob.centroid.x, 320, 0.1);
    EXPECT_NEAR(o.blob.centroid.y, 240, 0.1);
    // The major axis end points lie on the ellipse boundary (eq. 19-20 with l the full length).
    EXPECT_NEAR(cv::norm(o.blob.major_axis_ends[0] - o.blob.major_axis_ends[1]), 180.0, 2.0);
  }
}

// Eq. 11-22 on exact moments: a 2:1 axis-aligned rectangle of pixels has the known results.
TEST(Moments, ClosedFormOnARectangle) {
  RawMoments m;
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 20; ++x) m.add(100 + x, 50 + y);
  }
  const Blob b = blob_from_moments(m);
  EXPECT_DOUBLE_EQ(b.area, 200);
  EXPECT_DOUBLE_EQ(b.centroid.x, 109.5);
  EXPECT_DOUBLE_EQ(b.centroid.y, 54.5);
  EXPECT_NEAR(b.mu20 / 200, (20.0 * 20 - 1) / 12, 1e-9);  // variance of 0..19
  EXPECT_NEAR(b.mu02 / 200, (10.0 * 10 - 1) / 12, 1e-9);
  EXPECT_NEAR(b.mu11, 0, 1e-9);
  EXPECT_NEAR(b.orientation, 0, 1e-12);
  EXPECT_NEAR(b.major_axis, std::sqrt(16 * (399.0 / 12)), 1e-9);
}

// The centroid of an anti-aliased disc at a sub-pixel position is found within 0.3 px.
TEST(Tracking, AntiAliasedDiscCentroid) {
  for (const cv::Point2d& c :
       {cv::Point2d(100.3, 200.7), cv::Point2d(321.61, 99.12), cv::Point2d(500.5, 400.25)}) {
    cv::Mat image = grey_image();
    cv::circle(image, cv::Point(cvRound(c.x * 256), cvRound(c.y * 256)), 20 * 256, kRed, cv::FILLED,
               cv::LINE_AA, 8);
    BlobTracker tracker(params(), image.size());
    const Observation o = tracker.track(image);
    ASSERT_TRUE(o.found);
    EXPECT_LT(cv::norm(o.blob.centroid - c), 0.3) << c;
  }
}

// The window is twice the apparent diameter, capped at 24% x 32% of the image, grows after a
// miss, and the whole image is searched after three.
TEST(SearchWindow, SizingCappingGrowthAndFallback) {
  const SearchWindowParams p;
  const cv::Size image(640, 480);
  EXPECT_EQ(search_window({320, 240}, 40, 0, image, p), cv::Rect(280, 200, 80, 80));
  const cv::Rect capped = search_window({320, 240}, 200, 0, image, p);
  EXPECT_EQ(capped.width, cvRound(0.24 * 640));
  EXPECT_EQ(capped.height, cvRound(0.32 * 480));
  EXPECT_EQ(search_window({320, 240}, 40, 1, image, p).width, 120);
  EXPECT_EQ(search_window({320, 240}, 40, 3, image, p), cv::Rect(0, 0, 640, 480));
  EXPECT_EQ(search_window({5, 5}, 40, 0, image, p), cv::Rect(0, 0, 45, 45)) << "clipped";
  EXPECT_EQ(search_window({320, 240}, 2, 0, image, p).width, p.min_side);
}

// Tracking mode processes only the window; after the ball leaves, the window grows, then the
// whole image is searched, and the ball is found again when it comes back.
TEST(Tracking, LeavesAndComesBack) {
  BlobTracker tracker(params(), {640, 480});
  cv::Mat with_ball = grey_image();
  cv::circle(with_ball, {300, 200}, 20, kRed, cv::FILLED);
  Observation o = tracker.track(with_ball);
  EXPECT_FALSE(o.tracking) << "first frame: whole image";
  o = tracker.track(with_ball);
  EXPECT_TRUE(o.tracking);
  EXPECT_LE(o.window.width, 90);
  const cv::Mat empty = grey_image();
  for (int miss = 0; miss < 3; ++miss) {
    o = tracker.track(empty);
    EXPECT_FALSE(o.found);
    EXPECT_EQ(o.misses, miss);
    EXPECT_TRUE(o.tracking);
  }
  o = tracker.track(empty);
  EXPECT_FALSE(o.tracking) << "after 3 misses the whole image";
  cv::Mat elsewhere = grey_image();
  cv::circle(elsewhere, {600, 60}, 20, kRed, cv::FILLED);
  o = tracker.track(elsewhere);
  ASSERT_TRUE(o.found);
  EXPECT_NEAR(o.blob.centroid.x, 600, 0.5);
  EXPECT_TRUE(tracker.track(elsewhere).tracking);
}

// When the ball hides, a small red distractor is not taken for it, even in full-frame search; the
// ball is found again when it returns, and after a long absence any size is accepted again.
TEST(Tracking, DistractorIsNotTakenForTheHiddenBall) {
  BlobTracker::Params p = params();
  p.forget_size_after_misses = 20;
  BlobTracker tracker(p, {640, 480});
  cv::Mat with_ball = grey_image(), sticker_only = grey_image();
  cv::circle(with_ball, {300, 200}, 25, kRed, cv::FILLED);
  for (cv::Mat* m : {&with_ball, &sticker_only}) cv::circle(*m, {550, 400}, 6, kRed, cv::FILLED);
  ASSERT_TRUE(tracker.track(with_ball).found);
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(tracker.track(sticker_only).found) << k;
  EXPECT_TRUE(tracker.track(with_ball).found);
  for (int k = 0; k < 20; ++k) tracker.track(sticker_only);
  const Observation o = tracker.track(sticker_only);
  EXPECT_TRUE(o.found) << "the size was forgotten";
  EXPECT_NEAR(o.blob.centroid.x, 550, 0.5);
}

// A prediction moves the window: a ball far from its last position is found where predicted.
TEST(Tracking, PredictedPositionCentresTheWindow) {
  BlobTracker tracker(params(), {640, 480});
  cv::Mat a = grey_image(), b = grey_image();
  cv::circle(a, {200, 200}, 15, kRed, cv::FILLED);
  cv::circle(b, {400, 300}, 15, kRed, cv::FILLED);
  tracker.track(a);
  EXPECT_FALSE(tracker.track(b).found) << "window around the old place";
  BlobTracker predicted(params(), {640, 480});
  predicted.track(a);
  const Observation o = predicted.track(b, cv::Point2d(395, 305));
  EXPECT_TRUE(o.found && o.tracking);
}

// Robustness: lighting x0.5 to x1.5, a shadow across the ball, a specular highlight, partial
// occlusion (the centroid of the visible part), small red distractors, an empty frame.
TEST(Tracking, Robustness) {
  const cv::Point centre(320, 240);
  for (double gain : {0.5, 0.75, 1.25, 1.5}) {
    cv::Mat image = grey_image();
    cv::circle(image, centre, 25, kRed, cv::FILLED);
    image.convertTo(image, -1, gain);
    const Observation o = BlobTracker(params(), image.size()).track(image);
    ASSERT_TRUE(o.found) << gain;
    EXPECT_LT(cv::norm(o.blob.centroid - cv::Point2d(centre)), 0.1) << gain;
  }
  {  // a shadow darkens the left half
    cv::Mat image = grey_image();
    cv::circle(image, centre, 25, kRed, cv::FILLED);
    image(cv::Rect(0, 0, 320, 480)) *= 0.45;
    const Observation o = BlobTracker(params(), image.size()).track(image);
    ASSERT_TRUE(o.found);
    EXPECT_LT(cv::norm(o.blob.centroid - cv::Point2d(centre)), 0.6);
  }
  {  // a white highlight inside the ball
    cv::Mat image = grey_image();
    cv::circle(image, centre, 25, kRed, cv::FILLED);
    cv::circle(image, centre + cv::Point(-8, -8), 4, cv::Scalar(255, 255, 255), cv::FILLED);
    const Observation o = BlobTracker(params(), image.size()).track(image);
    ASSERT_TRUE(o.found);
    EXPECT_LT(cv::norm(o.blob.centroid - cv::Point2d(centre)), 0.6);
  }
  {  // the right half hidden: the centroid of the visible half
    cv::Mat image = grey_image();
    cv::circle(image, centre, 25, kRed, cv::FILLED);
    image(cv::Rect(320, 0, 320, 480)) = kGrey;
    const Observation o = BlobTracker(params(), image.size()).track(image);
    ASSERT_TRUE(o.found);
    EXPECT_NEAR(o.blob.centroid.x, 320 - 4 * 25 / (3 * M_PI) - 0.5, 0.6);  // half-disc centroid
  }
  {  // distractors: the largest region wins, and they are counted
    cv::Mat image = grey_image();
    cv::circle(image, centre, 25, kRed, cv::FILLED);
    for (int i = 0; i < 5; ++i) cv::circle(image, {60 + 100 * i, 420}, 4, kRed, cv::FILLED);
    const Observation o = BlobTracker(params(), image.size()).track(image);
    ASSERT_TRUE(o.found);
    EXPECT_EQ(o.num_regions, 6);
    EXPECT_LT(cv::norm(o.blob.centroid - cv::Point2d(centre)), 0.1);
  }
  {  // only distractors below the minimum area: nothing found
    cv::Mat image = grey_image();
    cv::circle(image, {100, 100}, 2, kRed, cv::FILLED);
    const Observation o = BlobTracker(params(), image.size()).track(image);
    EXPECT_FALSE(o.found);
    EXPECT_EQ(o.num_regions, 1);
  }
  EXPECT_FALSE(BlobTracker(params(), {640, 480}).track(cv::Mat::zeros(480, 640, CV_8UC3)).found);
  EXPECT_THROW(BlobTracker(params(), {640, 480}).track(cv::Mat::zeros(240, 320, CV_8UC3)),
               std::invalid_argument);
}

// On the simulator's frames (lighting changes, noise, distractors, the wooden table) the blob's
// centroid is the true ball image's centre within 0.3 px in both cameras.
TEST(Tracking, SimulatedFramesAgainstTruth) {
  sim::SimParams p;
  p.lighting.gain_amplitude = 0.3;  // harsher than the default
  p.lighting.gain_period = 8;
  p.frame_rate = 4;
  sim::CameraSimulator simulator(p);
  std::array<BlobTracker, 2> trackers{BlobTracker(params(), {640, 480}),
                                      BlobTracker(params(), {640, 480})};
  sim::StereoFrame frame;
  double worst = 0;
  for (int64_t k = 0; k < 80; ++k) {
    simulator.render(k, {}, frame);
    for (int i = 0; i < 2; ++i) {
      const Observation o =
          trackers[static_cast<size_t>(i)].track(frame.image[static_cast<size_t>(i)]);
      ASSERT_TRUE(o.found) << "frame " << k << " camera " << i;
      if (k > 0) {
        EXPECT_TRUE(o.tracking);
      }
      // The true image of the ball: centroid of its coverage.
      const cv::Mat cov = simulator.renderer(i).ball_coverage(frame.ball, p.ball_radius);
      const cv::Moments m = cv::moments(cov);
      const cv::Point2d truth(m.m10 / m.m00, m.m01 / m.m00);
      worst = std::max(worst, cv::norm(o.blob.centroid - truth));
    }
  }
  EXPECT_LT(worst, 0.3);
  std::printf("worst centroid error on simulated frames: %.3f px\n", worst);
}

// A colour range learned from a sample of the ball holds the ball and not the table.
TEST(ColorThresholds, LearnedFromASample) {
  sim::CameraSimulator simulator(sim::SimParams{});
  sim::StereoFrame frame;
  simulator.render(0, {}, frame);
  const Eigen::Vector2d projected = *simulator.camera(0).project(frame.ball);
  const cv::Point2d c(projected.x(), projected.y());
  const ColorThresholds learned =
      ColorThresholds::learn(frame.image[0], cv::Rect(cvRound(c.x) - 8, cvRound(c.y) - 8, 16, 16));
  const uint8_t table[3] = {66, 112, 158};  // the wooden table's colour, lit
  EXPECT_FALSE(ColorDetector(learned).is_object(table)) << "the table is not the ball";
  BlobTracker::Params tuned;
  tuned.color = learned;
  const Observation o = BlobTracker(tuned, {640, 480}).track(frame.image[0]);
  ASSERT_TRUE(o.found);
  EXPECT_LT(cv::norm(o.blob.centroid - c), 3.0);
  EXPECT_THROW(ColorThresholds::learn(frame.image[0], cv::Rect(700, 10, 5, 5)),
               std::invalid_argument);
}

}  // namespace
}  // namespace sg::vision
