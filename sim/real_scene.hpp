#pragma once

/// Real-scene test data: the red ball composited onto real photographs and video that Debian's
/// opencv-doc package ships, with a red-brown cloth larger than the ball, a red book that stays
/// put, lighting drift, sensor noise, MJPG (per-frame JPEG) compression, a panel that slides
/// over the ball, gripper fingers that close on it, and the ball leaving the view. Every frame's
/// truth (centre, radius, visible share of the disc) is known exactly, so a benchmark can say
/// how often the product's tracker finds the ball, and where.
///
///     sg::sim::RealScene scene(sg::sim::standard_real_scenes(1440)[0]);
///     cv::Mat bgr;  sg::sim::RealSceneTruth truth;
///     for (int k = 0; k < scene.params().frames; ++k) {
///       scene.render(k, bgr, truth);
///       ... tracker.track(bgr) against truth.centre, truth.visible ...
///     }
///
/// A cycle of 720 frames: 0-299 the ball moves in view; 300-359 a panel's straight edge sweeps
/// over it (visible 1 to 0); 360-449 it is behind the panel; 450-509 the panel sweeps back;
/// 510-599 two fingers close on it from the sides (visible down to about half); 600-719 it is
/// out of the view. The panel's edge and the fingers are placed relative to the ball, so every
/// visible share from 1 to 0 occurs. The ball's path (a Lissajous figure over the left two
/// thirds of the image, radius 16-28 px) never meets the cloth.

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <string>
#include <vector>

namespace sg::sim {

/// The folder with opencv-doc's data: $SG_OPENCV_DATA, else
/// /usr/share/doc/opencv-doc/examples/data.
std::string opencv_data_dir();

struct RealSceneParams {
  std::string name = "home";
  std::string background = "home.jpg";  ///< in opencv_data_dir(): a photograph or a video
  int frames = 1440;
  uint64_t seed = 1;
  bool cloth = true;         ///< a red-brown cloth, about 25 times the ball's area
  bool red_book = true;      ///< a red book 60x36 px with a yellow band, fixed (static clutter)
  bool lighting = true;      ///< exposure 0.65-1.25 and colour-temperature drift
  double noise_sigma = 3.0;  ///< grey levels of Gaussian sensor noise
  int jpeg_quality = 80;     ///< per-frame JPEG (MJPG); 0: none
  bool occlusion = true;     ///< panel, fingers and out-of-view segments (else always visible)
};

/// What frame k shows.
struct RealSceneTruth {
  cv::Point2d centre;    ///< px, image coordinates (origin at the top-left pixel's centre)
  double radius = 0;     ///< px
  double visible = 0;    ///< share of the ball's disc that is visible, 0 to 1
  bool in_view = false;  ///< false: the ball is not in the image at all
};

/// The generator (deterministic: the same parameters give the same bytes).
class RealScene {
 public:
  /// Throws std::runtime_error naming the file (and `apt-get install opencv-doc`) when the
  /// background cannot be read.
  explicit RealScene(const RealSceneParams& params);

  /// Frame `k` (0 <= k < frames) as 640x480 CV_8UC3 BGR, and its truth.
  void render(int k, cv::Mat& bgr, RealSceneTruth& truth);

  const RealSceneParams& params() const { return params_; }

 private:
  void background(int k, cv::Mat& out);
  void draw_ball(const RealSceneTruth& t, cv::Mat& image, cv::Mat& coverage) const;
  void draw_clutter(cv::Mat& image) const;
  double occlude(int phase, const RealSceneTruth& t, cv::Mat& image, cv::Mat& coverage) const;
  void degrade(int k, cv::Mat& image);
  void make_noise_bank();

  RealSceneParams params_;
  cv::Mat photo_;           // a still background, 640x480
  cv::VideoCapture video_;  // or a video's frames
  int video_frames_ = 0;
  cv::Mat texture_;             // the cloth's weave, CV_32F
  std::vector<cv::Mat> noise_;  // Gaussian fields, CV_16SC3, a margin larger than the frame
};

/// The benchmark's and tests' set: home.jpg (houses against the sky) with the cloth, fruits.jpg (an
/// orange and red cabbage) and vtest.avi (people walking) with the cloth, `frames` each, the book
/// in all. (Not in it: a ball in front of a red surface of its own colour, baboon.jpg's nose, which
/// one camera's colour segmentation cannot part from it; and a second red ball that stays put,
/// which one camera cannot tell from the ball until one of them moves.)
std::vector<RealSceneParams> standard_real_scenes(int frames);

}  // namespace sg::sim
