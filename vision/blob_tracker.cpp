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

namespace {

/// A whole disc's moments give equal axes (eq. 16-17), and it fills pi / 4 of a square box.
/// (A disc with a small cap hidden already has l / w above 1.08: 0.93 of it visible gives 1.1.)
bool looks_like_a_whole_disc(const Blob& b, const Region& region) {
  const cv::Rect box = region.box();
  if (b.minor_axis <= 0 || box.width < 4 || box.height < 4) return false;
  const double fill = b.area / box.area(), aspect = double(box.width) / box.height;
  return b.major_axis / b.minor_axis < 1.08 && std::abs(fill - M_PI / 4) < 0.05 &&
         std::abs(aspect - 1) < 0.1;
}

}  // namespace

BlobTracker::BlobTracker(const Params& params, cv::Size image_size)
    : params_(params),
      size_(image_size),
      detector_(params.color),
      segmenter_(image_size),
      adaptation_(params.color, params.adaptation) {
  if (image_size.width <= 0 || image_size.height <= 0)
    throw std::invalid_argument("BlobTracker: image size must be positive");
  edge_.reserve(8192);
}

void BlobTracker::reset() {
  has_track_ = false;
  misses_ = 0;
}

Observation BlobTracker::track(const cv::Mat& bgr, const std::optional<cv::Point2d>& predicted) {
  const Detection d = detect(bgr, predicted);
  return accept(d, d.best);
}

ScoreContext BlobTracker::context(const std::optional<cv::Point2d>& predicted,
                                  const std::optional<double>& expected_radius) const {
  ScoreContext x;
  if (has_track_) {
    x.expected_centre = predicted.value_or(last_centre_);
    x.motion_sigma = params_.scoring.motion_scale * std::max(last_diameter_, 10.0) * (1 + misses_);
  }
  if (expected_radius) {
    x.expected_radius = expected_radius;
  } else if (has_track_ && misses_ < params_.forget_size_after_misses) {
    x.expected_radius = last_diameter_ / 2;
  }
  x.colour = colour_.estimate();
  return x;
}

Candidate BlobTracker::describe(const Region& region) {
  Candidate c;
  c.blob = blob_from_moments(region.moments);
  c.centre = c.blob.centroid;
  c.radius = std::sqrt(c.blob.area / M_PI);
  c.mean_r = region.mean_r(), c.mean_g = region.mean_g();
  if (params_.selection == Selection::kLargest) {
    c.radius = c.blob.major_axis / 2;
    return c;
  }
  for (const Clutter& k : clutter_) {
    c.clutter |= k.frames >= params_.clutter_frames &&
                 cv::norm(k.centre - c.blob.centroid) <= params_.clutter_distance &&
                 std::abs(std::log(c.blob.area / k.area)) < 0.2;
  }
  if (c.radius > params_.scoring.max_radius) {
    c.too_large = true;
    return c;
  }
  if (looks_like_a_whole_disc(c.blob, region)) {
    c.whole_disc = true;
    return c;
  }
  edge_.clear();
  const cv::Mat mask = segmenter_.mask_of(region);
  append_edge_points(mask, segmenter_.mask_origin(), segmenter_.window(), edge_);
  const BallFit fit = fitter_.fit(edge_, params_.fit);
  if (!fit.ok) {
    c.support = 0;
    return c;
  }
  c.fitted = fit.support < params_.scoring.fit_below_support;
  if (c.fitted) c.centre = fit.centre, c.arc = fit.arc;
  c.radius = fit.radius;
  c.support = fit.support;
  c.fit_rms = fit.rms;
  return c;
}

cv::Rect BlobTracker::next_window(const std::optional<cv::Point2d>& predicted) const {
  const cv::Rect all(0, 0, size_.width, size_.height);
  if (!has_track_ || misses_ >= params_.window.misses_before_full_frame) return all;
  const cv::Rect w = search_window(predicted.value_or(last_centre_), last_diameter_, misses_, size_,
                                   params_.window);
  return w.empty() ? all : w;  // empty: the prediction left the image, search it all
}

Detection BlobTracker::detect(const cv::Mat& bgr, const std::optional<cv::Point2d>& predicted,
                              const std::optional<double>& expected_radius) {
  if (bgr.type() != CV_8UC3 || bgr.size() != size_)
    throw std::invalid_argument("BlobTracker: expected a " + std::to_string(size_.width) + "x" +
                                std::to_string(size_.height) + " BGR image");
  ++frame_;
  Detection d;
  d.image = bgr;
  Observation& o = d.frame;
  o.misses = misses_;
  o.window = next_window(predicted);
  o.tracking = o.window != cv::Rect(0, 0, size_.width, size_.height);
  int min_area = params_.min_area;
  if (has_track_ && misses_ < params_.forget_size_after_misses) {
    min_area = std::max(min_area, static_cast<int>(params_.min_area_fraction_of_last * last_area_));
  }
  const Segmentation s = segmenter_.run(bgr, o.window, detector_, min_area);
  o.num_regions = s.num_regions;
  ScoreContext x = context(predicted, expected_radius);
  if (s.num_candidates > 0) x.largest_area = static_cast<double>(s.regions[0].moments.m00);
  // A track that is new or has missed must start again from a candidate that looks like a ball.
  const bool acquiring = !has_track_ || misses_ > 0;
  double best = acquiring ? std::min(params_.scoring.max_cost, params_.scoring.acquire_max_cost)
                          : params_.scoring.max_cost;
  for (int k = 0; k < s.num_candidates; ++k) {
    Candidate& c = d.candidates[static_cast<size_t>(k)];
    c = describe(s.regions[static_cast<size_t>(k)]);
    ++d.count;
    if (params_.selection == Selection::kLargest) break;  // the largest is the target
    c.cost = candidate_cost(c, x, params_.scoring);
    if (acquiring && !c.whole_disc && !(c.support >= params_.scoring.acquire_min_support)) continue;
    if (c.cost <= best) best = c.cost, d.best = k;
  }
  if (params_.selection == Selection::kLargest && d.count > 0) d.best = 0;
  o.candidates = d.count;
  return d;
}

// Regions other than the ball, far from it, that stay put frame after frame are background.
void BlobTracker::learn_clutter(const Detection& d, int index) {
  if (params_.clutter_frames <= 0) return;
  const Candidate& ball = d.candidates[static_cast<size_t>(index)];
  for (int k = 0; k < d.count; ++k) {
    const Candidate& c = d.candidates[static_cast<size_t>(k)];
    if (k == index || cv::norm(c.blob.centroid - ball.centre) < 3 * 2 * ball.radius) continue;
    Clutter* slot = &clutter_[0];
    bool matched = false;
    for (Clutter& e : clutter_) {
      if (e.frames > 0 && cv::norm(e.centre - c.blob.centroid) <= params_.clutter_distance &&
          std::abs(std::log(c.blob.area / e.area)) < 0.2) {
        slot = &e, matched = true;
        break;
      }
      if (e.last_seen < slot->last_seen) slot = &e;  // else the longest unseen is replaced
    }
    if (!matched) *slot = Clutter{c.blob.centroid, c.blob.area, 0, 0};
    ++slot->frames;
    slot->last_seen = frame_;
  }
}

// A confident detection of the whole ball teaches its colour: the chromaticity for the score,
// and the pixels of its image for the detector's ranges.
void BlobTracker::learn_colour(const Detection& d, const Candidate& ball, double confidence) {
  if (confidence < 0.5 || !(ball.whole_disc || ball.support >= 0.8)) return;
  colour_.add(ball.mean_r, ball.mean_g);
  if (ball.fitted || d.image.empty()) return;
  // Only the window's pixels: they are all a region decode of the frame holds (jpeg_region.hpp).
  const cv::Rect& w = d.frame.window;
  const cv::Point2d centre = ball.centre - cv::Point2d(w.x, w.y);
  if (adaptation_.learn(d.image(w), centre, ball.radius))
    detector_ = ColorDetector(adaptation_.thresholds());
}

Observation BlobTracker::accept(const Detection& d, int index) {
  Observation o = d.frame;
  if (index < 0 || index >= d.count) {
    // >=: forget_size_after_misses may be 0; forget() is a no-op once the ranges are configured.
    if (has_track_ && ++misses_ >= params_.forget_size_after_misses && adaptation_.forget())
      detector_ = ColorDetector(adaptation_.thresholds());
    return o;
  }
  const Candidate& c = d.candidates[static_cast<size_t>(index)];
  o.found = true;
  o.blob = c.blob;
  o.centre = c.centre;
  o.radius = c.radius;
  o.fit_support = c.support;
  o.arc = c.arc;
  o.confidence = params_.selection == Selection::kLargest ? 1.0 : std::exp(-c.cost / 4);
  if (params_.selection == Selection::kScored) {
    learn_clutter(d, index);
    learn_colour(d, c, o.confidence);
  }
  // The size of a nearly hidden ball's circle is too uncertain to keep (unless there is none).
  const bool sized = params_.selection == Selection::kLargest || c.whole_disc ||
                     c.support >= params_.scoring.size_min_support || !has_track_;
  has_track_ = true;
  last_centre_ = c.centre;
  if (sized) last_diameter_ = 2 * c.radius;
  last_area_ = c.blob.area;
  misses_ = 0;
  return o;
}

}  // namespace sg::vision
