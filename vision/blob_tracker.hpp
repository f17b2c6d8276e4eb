#pragma once

#include <opencv2/core.hpp>
#include <optional>

#include "vision/color_detector.hpp"
#include "vision/moments.hpp"
#include "vision/segmentation.hpp"

namespace sg::vision {

/// The paper's search window (section 5.1): centred on the last known (or a predicted) position,
/// its side `diameter_factor` times the apparent diameter, at most 24% of the image width and 32%
/// of its height. After a miss it grows by `growth`; after `misses_before_full_frame` misses the
/// whole image is searched.
struct SearchWindowParams {
  double diameter_factor = 2.0;
  double max_width_fraction = 0.24;
  double max_height_fraction = 0.32;
  int min_side = 24;    ///< px, so a tiny or new blob still gets a usable window
  double growth = 1.5;  ///< per consecutive miss
  int misses_before_full_frame = 3;
};

/// The window around `centre` for a blob `diameter` px across after `misses` consecutive misses,
/// clipped to the image (misses >= misses_before_full_frame: the whole image).
cv::Rect search_window(const cv::Point2d& centre, double diameter, int misses, cv::Size image,
                       const SearchWindowParams& params);

/// What one camera's frame gave.
struct Observation {
  bool found = false;
  bool tracking = false;  ///< true: only the search window was processed
  Blob blob;              ///< valid when found
  cv::Rect window;        ///< the window processed (the whole image when not tracking)
  int num_regions = 0;    ///< regions of the object's colour in the window
  int misses = 0;         ///< consecutive misses before this frame
};

/// Detection, segmentation and moment tracking of one camera (sections 5.1-5.3).
///
///     BlobTracker left(params, {640, 480});
///     Observation o = left.track(frame);                 // or track(frame, predicted_pixel)
///     if (o.found) draw_cross(o.blob.centroid);
class BlobTracker {
 public:
  struct Params {
    ColorThresholds color;
    SearchWindowParams window;
    int min_area = 30;  ///< px; smaller regions of the colour are ignored (section 5.2)
    /// While a track is recent, a region must also be at least this fraction of the ball's last
    /// area: a red sticker a few percent of the ball's size is not taken for it when it hides.
    double min_area_fraction_of_last = 0.2;
    /// Misses after which the ball's last size is forgotten (it may come back at any size).
    int forget_size_after_misses = 150;
  };

  BlobTracker(const Params& params, cv::Size image_size);

  /// Processes one frame (CV_8UC3 BGR of the size given at construction).
  Observation track(const cv::Mat& bgr, const std::optional<cv::Point2d>& predicted = std::nullopt);

  /// Forgets the track: the next frame is searched whole.
  void reset();

  const Params& params() const { return params_; }

 private:
  Params params_;
  cv::Size size_;
  ColorDetector detector_;
  Segmenter segmenter_;
  bool has_track_ = false;
  cv::Point2d last_centre_;
  double last_diameter_ = 0;
  double last_area_ = 0;
  int misses_ = 0;
};

}  // namespace sg::vision
