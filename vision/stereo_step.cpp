#include "vision/stereo_step.hpp"

#include <spdlog/spdlog.h>

#include <cmath>

#include "vision/image_message.hpp"
#include "vision/triangulation.hpp"

namespace sg::vision {

using stereograsp::point3_t;

StereoStep::StereoStep(const BlobTracker::Params& params, cv::Size size,
                       std::optional<StereoCalibration> calibration)
    : trackers_{BlobTracker(params, size), BlobTracker(params, size)},
      size_(size),
      calibration_(std::move(calibration)) {}

void StereoStep::reset_size(cv::Size size) {
  spdlog::warn("frame size changed to {}x{}: tracking restarts", size.width, size.height);
  size_ = size;
  trackers_ = {BlobTracker(trackers_[0].params(), size), BlobTracker(trackers_[1].params(), size)};
}

StereoOutput StereoStep::process(const cv::Mat& left, const cv::Mat& right, int64_t frame_number,
                                 int64_t utime,
                                 const std::array<std::optional<cv::Point2d>, 2>& predicted) {
  const cv::Mat* images[2] = {&left, &right};
  StereoOutput out;
  for (size_t i = 0; i < 2; ++i) {
    if (images[i]->size() != size_) reset_size(images[i]->size());
    out.observation[i] = trackers_[i].track(*images[i], predicted[i]);
    counts_.found[i] += out.observation[i].found;
    counts_.tracking[i] += out.observation[i].tracking;
    out.blob[i] =
        to_blob_t(out.observation[i], static_cast<int8_t>(i), frame_number, utime);
  }
  ++counts_.pairs;
  if (calibration_) out.position = position_of(out.observation, *calibration_, utime);
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
  // eq. 26, refined on the reprojection error, with its uncertainty
  const auto t = triangulate({&calibration.left, &calibration.right},
                             {{o[0].blob.centroid.x, o[0].blob.centroid.y},
                              {o[1].blob.centroid.x, o[1].blob.centroid.y}});
  for (int i = 0; i < 3; ++i) p.position[i] = t.position[i], p.position_sigma[i] = t.sigma[i];
  p.reprojection_error = t.reprojection_error;
  if (t.behind_camera) p.flags |= point3_t::FLAG_BEHIND_CAMERA;
  if (t.near_parallel) p.flags |= point3_t::FLAG_NEAR_PARALLEL_RAYS;
  if (t.reprojection_error > StereoStep::kLargeResidualPx) p.flags |= point3_t::FLAG_LARGE_RESIDUAL;
  return p;
}

}  // namespace sg::vision
