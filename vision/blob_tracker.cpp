#include "vision/blob_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sg::vision {

cv::Rect search_window(const cv::Point2d& centre, double diameter, int misses, cv::Size image,
                       const SearchWindowParams& p) {
  const cv::Rect whole(0, 0, image.width, image.height);
  if (misses >= p.misses_before_full_frame) return whole;
  const double grow = std::pow(p.growth, misses);
  const double side = p.diameter_factor * diameter * grow;
  const double max_w = p.max_width_fraction * image.width * grow;
  const double max_h = p.max_height_fraction * image.height * grow;
  const int w = static_cast<int>(
      std::lround(std::clamp(side, double(p.min_side), std::max(max_w, double(p.min_side)))));
  const int h = static_cast<int>(
      std::lround(std::clamp(side, double(p.min_side), std::max(max_h, double(p.min_side)))));
  const cv::Rect window(static_cast<int>(std::lround(centre.x - w / 2.0)),
                        static_cast<int>(std::lround(centre.y - h / 2.0)), w, h);
  return window & whole;
}

BlobTracker::BlobTracker(const Params& params, cv::Size image_size)
    : params_(params), size_(image_size), detector_(params.color), segmenter_(image_size) {
  if (image_size.width <= 0 || image_size.height <= 0)
    throw std::invalid_argument("BlobTracker: image size must be positive");
}

void BlobTracker::reset() {
  has_track_ = false;
  misses_ = 0;
}

Observation BlobTracker::track(const cv::Mat& bgr, const std::optional<cv::Point2d>& predicted) {
  if (bgr.type() != CV_8UC3 || bgr.size() != size_)
    throw std::invalid_argument("BlobTracker: expected a " + std::to_string(size_.width) + "x" +
                                std::to_string(size_.height) + " BGR image");
  Observation o;
  o.misses = misses_;
  o.tracking = has_track_ && misses_ < params_.window.misses_before_full_frame;
  o.window = o.tracking ? search_window(predicted.value_or(last_centre_), last_diameter_, misses_,
                                        size_, params_.window)
                        : cv::Rect(0, 0, size_.width, size_.height);
  if (o.window.empty()) {  // the prediction left the image: search it all
    o.tracking = false;
    o.window = cv::Rect(0, 0, size_.width, size_.height);
  }
  int min_area = params_.min_area;
  if (has_track_ && misses_ < params_.forget_size_after_misses) {
    min_area = std::max(min_area, static_cast<int>(params_.min_area_fraction_of_last * last_area_));
  }
  const Segmentation s = segmenter_.run(bgr, o.window, detector_, min_area);
  o.num_regions = s.num_regions;
  o.found = s.found;
  if (s.found) {
    o.blob = blob_from_moments(s.largest);
    has_track_ = true;
    last_centre_ = o.blob.centroid;
    last_diameter_ = o.blob.major_axis;
    last_area_ = o.blob.area;
    misses_ = 0;
  } else if (has_track_) {
    ++misses_;
  }
  return o;
}

}  // namespace sg::vision
