#pragma once

#include <array>
#include <cmath>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "vision/ball_fit.hpp"
#include "vision/ball_score.hpp"
#include "vision/color_adaptation.hpp"
#include "vision/color_detector.hpp"
#include "vision/color_model.hpp"
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
  Blob blob;              ///< valid when found: the chosen region's eq. 11-22
  cv::Point2d centre;     ///< the ball's centre: fitted circle when partly hidden, else centroid
  double radius = 0;      ///< px, of the ball's image
  double fit_support = std::nan("");  ///< of the fitted circle's circumference (NaN: no fit)
  uint64_t arc = 0;  ///< the outline's sectors the centre rests on (BallFit::arc); 0: not found
  double confidence = 0;  ///< 0..1, exp(-cost / 4) of the chosen candidate
  int candidates = 0;     ///< regions of at least the minimum area that were scored
  cv::Rect window;        ///< the window processed (the whole image when not tracking)
  int num_regions = 0;    ///< regions of the object's colour in the window
  int misses = 0;         ///< consecutive misses before this frame
};

/// How the tracker picks the ball among the regions of its colour.
enum class Selection {
  kLargest,  ///< the paper's rule (section 5.2): the largest region, its centroid (eq. 11)
  kScored,   ///< the lowest candidate_cost() (ball_score.hpp), a fitted centre when partly hidden
};

/// One frame's candidates, before one is accepted as the ball.
struct Detection {
  Observation frame;  ///< window, mode, regions, misses; found false
  cv::Mat image;      ///< the frame detected in (shared, not copied): accept() learns its colour
  std::array<Candidate, Segmentation::kMaxRegions> candidates;
  int count = 0;
  int best = -1;  ///< the candidate the camera alone would take (-1: none)
};

/// Detection, segmentation and moment tracking of one camera (sections 5.1-5.3), with the ball
/// chosen among the regions of its colour by a score (ball_score.hpp) or by the paper's
/// largest-region rule.
///
///     BlobTracker left(params, {640, 480});
///     Observation o = left.track(frame);                 // or track(frame, predicted_pixel)
///     if (o.found) draw_cross(o.centre);
///
/// A stereo caller splits the step: detect() in both cameras, choose a pair that agrees
/// (stereo_match.hpp), accept() it in each.
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
    Selection selection = Selection::kScored;
    ScoringParams scoring;
    BallFitParams fit;
    /// A region that stays within `clutter_distance` px and keeps its size for this many frames
    /// while the ball is tracked elsewhere is learned as background (0: never).
    int clutter_frames = 30;
    double clutter_distance = 2.0;
    /// The colour ranges narrowed to the ball's, within `color` (color_adaptation.hpp); they are
    /// forgotten with the ball's size (forget_size_after_misses).
    ColorAdaptationParams adaptation;
  };

  BlobTracker(const Params& params, cv::Size image_size);

  /// Processes one frame (CV_8UC3 BGR of the size given at construction).
  Observation track(const cv::Mat& bgr, const std::optional<cv::Point2d>& predicted = std::nullopt);

  /// The candidates of one frame, scored; `expected_radius` (px, from the ball's depth) replaces
  /// the last image's size in the score.
  Detection detect(const cv::Mat& bgr, const std::optional<cv::Point2d>& predicted = std::nullopt,
                   const std::optional<double>& expected_radius = std::nullopt);
  /// The pixels the next detect() with `predicted` reads: the search window while tracking, else
  /// the whole image. Nothing outside it is read, so a caller may decode only it (jpeg_region.hpp).
  cv::Rect next_window(const std::optional<cv::Point2d>& predicted = std::nullopt) const;
  /// Takes candidate `index` of `d` as the ball (-1: a miss) and updates the track.
  Observation accept(const Detection& d, int index);

  /// Forgets the track: the next frame is searched whole.
  void reset();

  const Params& params() const { return params_; }
  bool has_track() const { return has_track_; }
  /// The learned colour (ColorModel), for a report.
  const ColorModel& colour() const { return colour_; }
  /// The colour ranges detected with now (the configured ones, or narrowed to the ball's).
  const ColorThresholds& color_ranges() const { return detector_.thresholds(); }

 private:
  Candidate describe(const Region& region);
  ScoreContext context(const std::optional<cv::Point2d>& predicted,
                       const std::optional<double>& expected_radius) const;
  void learn_clutter(const Detection& d, int index);
  void learn_colour(const Detection& d, const Candidate& ball, double confidence);

  struct Clutter {
    cv::Point2d centre;
    double area = 0;
    int frames = 0;
    int64_t last_seen = 0;
  };

  Params params_;
  cv::Size size_;
  ColorDetector detector_;
  Segmenter segmenter_;
  BallFitter fitter_;
  std::vector<cv::Point2d> edge_;
  ColorModel colour_;
  ColorAdaptation adaptation_;
  std::array<Clutter, 16> clutter_{};
  int64_t frame_ = 0;
  bool has_track_ = false;
  cv::Point2d last_centre_;
  double last_diameter_ = 0;
  double last_area_ = 0;
  int misses_ = 0;
};

}  // namespace sg::vision
