#pragma once

#include <algorithm>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "vision/color_detector.hpp"
#include "vision/moments.hpp"

namespace sg::vision {

/// One 8-connected region of the object's colour: a candidate for the ball.
struct Region {
  RawMoments moments;                                ///< eq. 9, image coordinates
  int x_min = 0, y_min = 0, x_max = -1, y_max = -1;  ///< the pixels' extent, image coordinates
  int64_t sum_b = 0, sum_g = 0, sum_r = 0;           ///< colour sums over its pixels
  int32_t label = 0;                                 ///< its root label, until the next run()

  /// The pixels' bounding box.
  cv::Rect box() const { return {x_min, y_min, x_max - x_min + 1, y_max - y_min + 1}; }
  /// Mean normalized r and g (eq. 7) over the region's pixels.
  double mean_r() const { return double(sum_r) / std::max<int64_t>(1, sum_b + sum_g + sum_r); }
  double mean_g() const { return double(sum_g) / std::max<int64_t>(1, sum_b + sum_g + sum_r); }
};

/// The result of segmenting one window (section 5.2).
struct Segmentation {
  static constexpr int kMaxRegions = 8;
  int num_regions = 0;  ///< 8-connected regions of the object's colour, before the area filter
  bool found = false;   ///< a region of at least the minimum area exists
  RawMoments largest;   ///< moments of the largest region (the paper's target)
  /// The largest regions of at least the minimum area, largest first (at most kMaxRegions).
  std::array<Region, kMaxRegions> regions;
  int num_candidates = 0;
};

/// Detection (eq. 7-8), connected-component labelling and the sums of every region (raw
/// moments, extent, colour) in one pass over a window, merged per region after it: the largest
/// regions are the candidates, the largest the paper's target. Buffers are sized once for the
/// largest window, so tracking allocates nothing per frame.
///
///     Segmenter segmenter(image_size);
///     Segmentation s = segmenter.run(bgr, window, detector, /*min_area=*/30);
///     if (s.found) Blob blob = blob_from_moments(s.largest);
///     cv::Mat mask = segmenter.mask_of(s.regions[0]);   // its pixels, box grown by one
class Segmenter {
 public:
  explicit Segmenter(cv::Size max_size);

  Segmentation run(const cv::Mat& bgr, const cv::Rect& window, const ColorDetector& detector,
                   int min_area);

  /// A CV_8UC1 view (255 = the region) of `region`'s box grown by one pixel within the last
  /// window, valid until the next call; its pixel (0, 0) is image pixel mask_origin().
  cv::Mat mask_of(const Region& region);
  cv::Point mask_origin() const { return mask_origin_; }
  /// The last window run() processed (clipped to the image).
  const cv::Rect& window() const { return window_; }

 private:
  int32_t find(int32_t label);
  int32_t unite(int32_t a, int32_t b);
  void label_window(const cv::Mat& bgr, const ColorDetector& detector);
  void sum_regions();
  void keep_candidate(Segmentation& s, const Region& region) const;

  std::vector<int32_t> labels_;  // per pixel of the window, 0 for background
  std::vector<int32_t> parent_;  // union-find over provisional labels
  std::vector<Region> sums_;     // per root label
  std::vector<uint8_t> mask_;    // mask_of()'s pixels
  cv::Rect window_;
  cv::Point mask_origin_;
  int32_t next_ = 1;
};

}  // namespace sg::vision
