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
/// Two kernels give the same regions bit for bit (a test): kRuns, the default, classifies a row
/// at a time with the vectorized ColorDetector::classify, finds the runs of the colour 64
/// pixels at a time in its bits, labels runs (a run joins the runs above that touch it,
/// 8-connected) and adds each run's moments in closed form (sum of x over [a, b] = (a + b)(b - a +
/// 1) / 2, of x^2 = S(b) - S(a - 1), S(k) = k (k + 1)(2k + 1) / 6); kPixels labels pixel by pixel,
/// the reference. Labels are made in raster order in both, and a region's root is its smallest, so
/// the regions come out in the same order.
///
///     Segmenter segmenter(image_size);
///     Segmentation s = segmenter.run(bgr, window, detector, /*min_area=*/30);
///     if (s.found) Blob blob = blob_from_moments(s.largest);
///     cv::Mat mask = segmenter.mask_of(s.regions[0]);   // its pixels, box grown by one
class Segmenter {
 public:
  enum class Kernel { kRuns, kPixels };

  explicit Segmenter(cv::Size max_size, Kernel kernel = Kernel::kRuns);

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
  void label_runs(const cv::Mat& bgr, const ColorDetector& detector);
  int32_t label_of_run(int x0, int x1, size_t& above, size_t above_end);
  void paint_runs(const Region& region, const cv::Rect& box, cv::Mat& mask) const;

  /// A run of the colour in the window's row: pixels [x0, x1), window coordinates.
  struct Run {
    int32_t x0, x1, label;
  };
  void sum_regions();
  void keep_candidate(Segmentation& s, const Region& region) const;

  std::vector<int32_t> labels_;  // per pixel of the window, 0 for background
  std::vector<int32_t> parent_;  // union-find over provisional labels
  std::vector<Region> sums_;     // per root label
  std::vector<uint8_t> mask_;    // mask_of()'s pixels
  cv::Size max_size_;
  Kernel kernel_;
  std::vector<Run> runs_;              // kRuns: the window's runs, row by row
  std::vector<size_t> row_start_;      // kRuns: each row's first run, and the end
  size_t bits_per_row_ = 0;            // kRuns: words a row of window_bits_
  std::vector<uint64_t> window_bits_;  // kRuns: classify_rows()'s output for the window
  int first_bound_ = ClassifyRowsArgs{}.first_bound;  // kRuns: the bound classify_rows tests
                                                       // first, from the last window's tally
  cv::Rect window_;
  cv::Point mask_origin_;
  int32_t next_ = 1;
};

}  // namespace sg::vision
