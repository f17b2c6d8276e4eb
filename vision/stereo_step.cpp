#include "vision/stereo_step.hpp"

#include <spdlog/spdlog.h>

#include <cmath>

#include "vision/image_message.hpp"
#include "vision/sphere_image.hpp"
#include "vision/triangulation.hpp"

namespace sg::vision {

using stereograsp::point3_t;

StereoStep::StereoStep(const BlobTracker::Params& params, cv::Size size,
                       std::optional<StereoCalibration> calibration, const StereoMatchParams& match)
    : trackers_{BlobTracker(params, size), BlobTracker(params, size)},
      size_(size),
      calibration_(std::move(calibration)),
      match_(match) {}

void StereoStep::reset_size(cv::Size size) {
  spdlog::warn("frame size changed to {}x{}: tracking restarts", size.width, size.height);
  size_ = size;
  trackers_ = {BlobTracker(trackers_[0].params(), size), BlobTracker(trackers_[1].params(), size)};
  last_position_.reset();
}

// The ball's radius in `camera` where it was last placed, while that is recent (10 pairs).
std::optional<double> StereoStep::expected_radius(size_t camera) const {
  constexpr uint64_t kRecentPairs = 10;
  if (!calibration_ || !last_position_ || match_.ball_radius <= 0 ||
      counts_.pairs > last_position_pair_ + kRecentPairs)
    return std::nullopt;
  const double r = apparent_radius(camera == 0 ? calibration_->left : calibration_->right,
                                   *last_position_, match_.ball_radius);
  return std::isfinite(r) ? std::optional<double>(r) : std::nullopt;
}

cv::Rect StereoStep::next_window(size_t camera, cv::Size frame,
                                 const std::optional<cv::Point2d>& predicted) const {
  if (frame != size_) return {0, 0, frame.width, frame.height};
  return trackers_[camera].next_window(predicted);
}

std::array<int, 2> StereoStep::choose(const std::array<Detection, 2>& d) const {
  const BlobTracker::Params& p = trackers_[0].params();
  if (!calibration_ || p.selection != Selection::kScored) return {d[0].best, d[1].best};
  const StereoMatch m = match_stereo(d[0], d[1], *calibration_, p.scoring, match_);
  if (m.found()) return {m.left, m.right};
  std::array<int, 2> pick{-1, -1};  // no pair: a camera keeps the ball it is tracking
  for (size_t i = 0; i < 2; ++i) {
    if (trackers_[i].has_track() && d[i].frame.tracking) pick[i] = d[i].best;
  }
  return pick;
}

StereoOutput StereoStep::process(const cv::Mat& left, const cv::Mat& right, int64_t frame_number,
                                 int64_t utime,
                                 const std::array<std::optional<cv::Point2d>, 2>& predicted) {
  const cv::Mat* images[2] = {&left, &right};
  std::array<Detection, 2> d;
  for (size_t i = 0; i < 2; ++i) {
    if (images[i]->size() != size_) reset_size(images[i]->size());
    d[i] = trackers_[i].detect(*images[i], predicted[i], expected_radius(i));
  }
  const std::array<int, 2> pick = choose(d);
  StereoOutput out;
  for (size_t i = 0; i < 2; ++i) {
    out.observation[i] = trackers_[i].accept(d[i], pick[i]);
    counts_.found[i] += out.observation[i].found;
    counts_.tracking[i] += out.observation[i].tracking;
    out.blob[i] = to_blob_t(out.observation[i], static_cast<int8_t>(i), frame_number, utime);
  }
  ++counts_.pairs;
  if (calibration_) {
    out.position = position_of(out.observation, *calibration_, utime);
    if (out.position->visible && !(out.position->flags & point3_t::FLAG_BEHIND_CAMERA)) {
      last_position_ = Eigen::Vector3d(out.position->position[0], out.position->position[1],
                                       out.position->position[2]);
      last_position_pair_ = counts_.pairs;
    }
  }
  return out;
}

point3_t position_of(const std::array<Observation, 2>& o, const StereoCalibration& calibration,
                     int64_t utime) {
  point3_t p{};
  p.utime = utime;
  p.seen_by = static_cast<int8_t>((o[0].found ? point3_t::SEEN_LEFT : 0) |
                                  (o[1].found ? point3_t::SEEN_RIGHT : 0));
  p.visible = o[0].found && o[1].found;
  const double nan = std::nan("");
  for (int i = 0; i < 3; ++i) p.position[i] = p.position_sigma[i] = nan;
  p.reprojection_error = nan;
  if (!p.visible) return p;
  // eq. 26, refined on the reprojection error, with its uncertainty, from the pixels of the
  // ball's centre (the ellipse's centre lies off it: sphere_image.hpp)
  const auto t = triangulate(
      {&calibration.left, &calibration.right},
      {sphere_centre_pixel(calibration.left, {o[0].centre.x, o[0].centre.y}, o[0].radius),
       sphere_centre_pixel(calibration.right, {o[1].centre.x, o[1].centre.y}, o[1].radius)});
  for (int i = 0; i < 3; ++i) p.position[i] = t.position[i], p.position_sigma[i] = t.sigma[i];
  p.reprojection_error = t.reprojection_error;
  if (t.behind_camera) p.flags |= point3_t::FLAG_BEHIND_CAMERA;
  if (t.near_parallel) p.flags |= point3_t::FLAG_NEAR_PARALLEL_RAYS;
  if (t.reprojection_error > StereoStep::kLargeResidualPx) p.flags |= point3_t::FLAG_LARGE_RESIDUAL;
  return p;
}

}  // namespace sg::vision
