#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "sim/primitives.hpp"
#include "vision/camera_model.hpp"

namespace sg::sim {

/// The fixed part of the lab: a wooden table (the plane Z = 0, the robot's base on it), a tiled
/// wall with a poster behind the robot, the robot's base, and small red stickers of the ball's hue
/// (distractors). Rendered once per camera.
struct StaticSceneParams {
  double wall_x = -0.45;  ///< the wall is the plane X = wall_x, facing +X
  int distractors = 4;    ///< red stickers of 8-14 mm radius on the table and the wall
  Eigen::Vector3d to_light{0.35, -0.25, 1.0};  ///< direction toward the light (normalized in use)
  uint64_t seed = 1;
};

/// What changes from frame to frame in one camera's picture.
struct DynamicScene {
  /// The ball; several centres (over the exposure) blur it, one renders it sharp.
  std::vector<Eigen::Vector3d> ball_centres;
  double ball_radius = 0.035;
  Material ball_material;
  /// Boxes that are drawn with correct depth against the ball (the gripper).
  std::vector<Box> boxes;
  /// A flat panel drawn in front of everything (the occluder): four world corners, in order.
  std::optional<std::array<Eigen::Vector3d, 4>> panel;
  Eigen::Vector3d panel_colour{70, 80, 95};
  /// Exposure gain and per-channel (B, G, R) colour gain applied to the whole image.
  double gain = 1.0;
  Eigen::Vector3d colour_gain{1.0, 1.0, 1.0};
  /// Which frame of sensor noise to add (any integer; noise frames repeat with a long period).
  int64_t noise_frame = 0;
};

/// What the renderer measured of the ball in this camera.
struct BallVisibility {
  double silhouette_px = 0.0;  ///< area of the ball's image, pixels (inside the image)
  double visible_px = 0.0;     ///< of which not hidden by the gripper or the panel
};

/// Renders one camera's view of the simulated lab.
///
///     CameraRenderer renderer(camera, {.distractors = 4, .seed = 7}, /*noise_sigma=*/2.0);
///     cv::Mat image;
///     BallVisibility seen = renderer.render(scene, image);   // CV_8UC3, BGR
///
/// The ball is ray-cast (so off-axis it is the correct ellipse, lens distortion included), shaded
/// with a diffuse and a specular term, and anti-aliased by 4x4 supersampling of the pixels its
/// edge crosses. The same inputs always give the same bytes.
class CameraRenderer {
 public:
  CameraRenderer(const vision::CameraModel& camera, const StaticSceneParams& scene,
                 double noise_sigma);

  /// Renders into `image` (allocated on first use) and reports the ball's visibility.
  BallVisibility render(const DynamicScene& scene, cv::Mat& image) const;

  /// Fraction of each pixel covered by a ball alone in front of nothing (CV_32F); for tests.
  cv::Mat ball_coverage(const Eigen::Vector3d& centre, double radius) const;

  const cv::Mat& background() const { return background_; }
  const vision::CameraModel& camera() const { return camera_; }

 private:
  struct Hit {
    int object = -1;  // -1 nothing, 0 the ball, 1.. boxes
    double distance = 0.0;
    int face = -1;  // boxes: which face (BoxFromEye::intersect)
  };
  struct Objects;

  Eigen::Vector3d corner_ray(int x, int y) const {
    return corner_rays_[static_cast<size_t>(y) * (camera_.width() + 1) + static_cast<size_t>(x)];
  }
  void render_background(const StaticSceneParams& params);
  void make_noise(double sigma, uint64_t seed);
  std::optional<cv::Rect> screen_box(const std::vector<Eigen::Vector3d>& points) const;
  double render_region(const Objects& objects, const cv::Rect& region, cv::Mat& image,
                       cv::Mat* ball_coverage) const;
  double hidden_by_panel(const DynamicScene& scene, const cv::Rect& region,
                         const cv::Mat& ball_coverage, cv::Mat& image) const;
  void apply_exposure(const DynamicScene& scene, cv::Mat& image) const;
  /// The screen regions to ray-cast, (region, holds the ball): one per drawn ball centre (also
  /// kept in `ball_screens`, an empty one where a centre is not drawn) and one per box (also kept
  /// in objects.screen).
  std::vector<std::pair<cv::Rect, bool>> screen_regions(const DynamicScene& scene, Objects& objects,
                                                        std::vector<cv::Rect>& ball_screens) const;
  /// What render_sharp and render_blurred drew of the ball.
  struct BallImage;
  /// A sharp ball (at most one centre): every region drawn once, into `image`.
  BallImage render_sharp(const DynamicScene& scene,
                         const std::vector<std::pair<cv::Rect, bool>>& regions,
                         const std::vector<cv::Rect>& ball_screens, Objects& objects,
                         cv::Mat& image) const;
  /// Motion blur: the union of the regions drawn once per ball centre and averaged (the exposure).
  BallImage render_blurred(const DynamicScene& scene,
                           const std::vector<std::pair<cv::Rect, bool>>& regions,
                           const std::vector<cv::Rect>& ball_screens, Objects& objects,
                           cv::Mat& image) const;

  vision::CameraModel camera_;
  Eigen::Vector3d eye_;
  Eigen::Vector3d to_light_;
  std::vector<Eigen::Vector3d> corner_rays_;    // world-frame unit rays through pixel corners
  cv::Mat background_;                          // CV_8UC3
  std::vector<cv::Mat> noise_up_, noise_down_;  // CV_8UC3 positive and negative parts
};

}  // namespace sg::sim
