#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "vision/color_detector.hpp"
#include "vision/moments.hpp"

namespace sg::vision {

/// The result of segmenting one window (section 5.2).
struct Segmentation {
  int num_regions = 0;  ///< 8-connected regions of the object's colour, before the area filter
  bool found = false;   ///< a region of at least the minimum area exists
  RawMoments largest;   ///< moments of the largest region (the target)
};

/// Detection (eq. 7-8) and connected-component labelling in one pass over a window, then the
/// raw moments of every region in a second: the largest region is the target. Buffers are sized
/// once for the largest window, so tracking allocates nothing per frame.
///
///     Segmenter segmenter(image_size);
///     Segmentation s = segmenter.run(bgr, window, detector, /*min_area=*/30);
///     if (s.found) Blob blob = blob_from_moments(s.largest);
class Segmenter {
 public:
  explicit Segmenter(cv::Size max_size);

  Segmentation run(const cv::Mat& bgr, const cv::Rect& window, const ColorDetector& detector,
                   int min_area);

 private:
  int32_t find(int32_t label);
  int32_t unite(int32_t a, int32_t b);

  std::vector<int32_t> labels_;   // per pixel of the window, 0 for background
  std::vector<int32_t> parent_;   // union-find over provisional labels
  std::vector<RawMoments> sums_;  // per root label
};

}  // namespace sg::vision
