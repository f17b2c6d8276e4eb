#pragma once

/// The centre of a partly hidden ball's image from the part of its outline that meets the
/// background.
///
/// The centroid of the visible region (eq. 11) is not the ball's centre once an occluding panel or
/// the gripper's fingers hide part of it (about 0.4 radius off for a half hidden ball). A sphere
/// images as a circle (near enough for the ball's size and the cameras' field of view), and the
/// part of the region's boundary where the ball meets the background lies on that circle, while
/// the boundary against an occluder (a straight edge, a finger's rectangular bite) lies inside it
/// and no pixel of the region lies outside it. BallFitter fits that circle to the region's edge
/// points (append_edge_points) robustly, leaving the occluder's edges out:
///
///     std::vector<cv::Point2d> edge;  edge.reserve(8192);     // once
///     BallFitter fitter;                                       // once: its buffers are sized here
///     ...
///     edge.clear();
///     append_edge_points(mask, mask_origin, window, edge);    // the region's boundary
///     const BallFit f = fitter.fit(edge, BallFitParams{}, expected_radius_px);  // hint optional
///     if (f.ok && f.support < 0.9) centre = f.centre;          // partly hidden: the fitted centre
///
/// Figures (tests/vision/ball_fit_test.cpp): a whole rasterized disc, radius 8 to 40 px, within
/// 0.3 px; discs of which 40-60% is visible behind a straight edge at any angle, p95 centre error
/// under 1.5 px where the centroid is off by 0.4 radius.

#include <array>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

namespace sg::vision {

/// Edge points of a binary region: for each region pixel and each of its 4-neighbours that lies
/// inside `valid` (the searched window, clipped to the image) but not in the region, the midpoint
/// of the two pixel centres ((x±0.5, y) or (x, y±0.5)), in image coordinates (origin at the centre
/// of the top-left pixel). Neighbours outside `valid` give no point: the ball may go on there.
/// `mask` is CV_8UC1 (nonzero = region) whose pixel (0,0) is image pixel `origin`; a neighbour
/// beyond the mask is not in the region. Points are appended row by row (left, right, up, down
/// neighbour of each pixel); `out` allocates only when it grows past its capacity.
/// For a region whose pixels are those with centres within r of a point, the edge points lie
/// within about 0.5 px of that circle: each is halfway between a pixel inside and one outside.
/// Throws std::invalid_argument when `mask` is not empty and not CV_8UC1.
void append_edge_points(const cv::Mat& mask, cv::Point origin, const cv::Rect& valid,
                        std::vector<cv::Point2d>& out);

/// BallFitter's settings. Distances are in pixels of the image.
struct BallFitParams {
  double inlier_tolerance =
      1.0;  ///< px: |distance - radius| for an edge point to support the circle
  /// px: an edge point farther than radius + this from the centre is clearly outside the circle,
  /// which the true circle never has (no region pixel lies outside the ball's image).
  double outside_tolerance = 1.5;
  /// Score a hypothesis loses per point clearly outside it (an inlier gains at most 1).
  double outside_penalty = 2.0;
  double min_radius = 2.0, max_radius = 400.0;  ///< px
  int iterations = 64;  ///< hypotheses tried (deterministic: triples along the angular order)
  int min_inliers = 6;  ///< fewer inliers of the refined circle: no fit
  int refinements = 3;  ///< rounds of (inliers of the circle -> least-squares circle)
  int gauss_newton_steps = 6;  ///< per round, on the geometric distance
  /// Radius hint: a hypothesis of radius r loses hint_weight x points x (ln(r/hint)/hint_scale)^2
  /// of score, so circles near the expected radius win close calls; the refinement ignores it.
  double hint_scale = 0.25;   ///< ln units of radius
  double hint_weight = 0.05;  ///< fraction of the points
  double support_bin = 2.0;   ///< px of arc per bin of the support histogram (at most 720 bins)
  /// confidence = (1 - exp(-support / s)) exp(-(rms / q)^2 / 2) exp(-outside share / o).
  double confidence_support_scale = 0.25;  ///< s
  double confidence_rms_scale = 0.6;       ///< q, px
  double confidence_outside_scale = 0.1;   ///< o, of the points
};

/// A circle fitted to a region's edge points.
struct BallFit {
  bool ok = false;     ///< false: too few usable points, or no circle in the radius range
  cv::Point2d centre;  ///< px, image coordinates (same as the edge points')
  double radius = 0;   ///< px
  double support =
      0;            ///< 0..1: fraction of the circle's circumference covered by inlier edge points
  double rms = 0;   ///< px: inliers' radial residual
  int inliers = 0;  ///< edge points within inlier_tolerance of the circle
  int points = 0;   ///< edge points used: finite, |x|,|y| <= 1e9, subsampled to max_points
  int outside = 0;  ///< edge points clearly outside the circle (d > r + outside_tolerance)
  double confidence = 0;  ///< 0..1, from support, rms and the share of points outside the circle
  /// Which parts of the circle the fit rests on: bit k is set when the directions from the centre
  /// atan2(y - cy, x - cx) in [-pi + k pi/32, -pi + (k + 1) pi/32) hold at least half the inlier
  /// edge points a whole outline would put there at the least (arc_sector()), or lie between two
  /// sectors that do. sphere_image.hpp uses it to
  /// model the same fit on the ball's exact image (an ellipse off the optical axis).
  uint64_t arc = 0;
};

/// Number of sectors of BallFit::arc.
inline constexpr int kArcSectors = 64;
/// All sectors: the whole outline (a whole disc's centroid rests on all of it).
inline constexpr uint64_t kWholeArc = ~uint64_t{0};
/// The sector of BallFit::arc holding direction (dx, dy) from the centre.
int arc_sector(double dx, double dy);

/// Fits the ball's image, a circle, to the edge points of its visible region. Occluder edges
/// (straight runs, concave bites) lie INSIDE the true circle and no region point lies outside it,
/// so the fit maximises the points on the circle while penalising points outside it:
///
/// 1. Points. Non-finite points and points beyond 1e9 px are skipped; more than max_points are
///    subsampled evenly (every k-th, k real). They are centred on their mean (for conditioning)
///    and ordered by angle around it (a pseudo-angle, monotonic in the angle). The visible region
///    of a ball is near star-shaped around that mean, so neighbours in this order are neighbours
///    on the outline and a run of the order is a run of arc or of occluder edge.
/// 2. Hypotheses (RANSAC, Fischler & Bolles 1981, with deterministic samples): circles through
///    the triples (i, i+s, i+2s) of that order, s = n/3, n/5, n/8 and n/12 (triples spanning 2/3
///    down to 1/6 of the outline), at starts spread evenly over it: some triples lie wholly on the
///    ball's arc whatever its angle, and no random numbers make a frame's answer irreproducible.
///    Circles outside [min_radius, max_radius] or through (near) collinear points are rejected.
/// 3. Score (MSAC, Torr & Zisserman 2000): sum over points of max(0, 1 - (e/tol)^2), e = d - r,
///    minus outside_penalty per point with d > r + outside_tolerance, minus the radius-hint term.
///    A circle fitted to an occluder's straight edge has region points outside it or few inliers;
///    one fitted to part of the arc but too small has the rest of the arc outside it.
/// 4. Refinement on the best hypothesis's inliers: Kåsa's algebraic fit (I. Kåsa, "A circle
///    fitting procedure and its error analysis", IEEE Trans. Instrum. Meas. 25(1), 1976: linear
///    least squares on x^2 + y^2 + D x + E y + F = 0), then Gauss-Newton on the geometric distance
///    sum (|p_i - c| - r)^2 (N. Chernov, "Circular and Linear Regression", CRC 2010, ch. 4), which
///    removes Kåsa's bias toward small circles on short arcs; inliers are selected again with
///    the refined circle, `refinements` times.
/// 5. Support: the circumference is cut in bins of about support_bin px; support is the share of
///    bins holding an inlier. rms and the outside share come from the final circle; arc marks
///    the 64 sectors that hold at least half of the edge points a whole outline has there at the
///    least (1 per px of arc: 4-neighbour midpoints), and lone gaps between them.
///
/// fit() allocates nothing: its buffers are sized once in the constructor. It never throws on
/// its input and ends in a bounded number of steps (O(iterations x points)); about 10 µs for
/// 200 points on a 2020 x86 core.
class BallFitter {
 public:
  /// `max_points`: the most edge points used by one fit (at least 3); more are subsampled.
  explicit BallFitter(size_t max_points = 8192);

  /// The circle of `edge` (image coordinates). `radius_hint`: the expected radius in px (from the
  /// ball's depth or its last image), a soft preference; absent, non-finite or <= 0: none.
  BallFit fit(const std::vector<cv::Point2d>& edge, const BallFitParams& params,
              std::optional<double> radius_hint = std::nullopt);

  size_t max_points() const { return max_points_; }

 private:
  struct Circle {
    double x = 0, y = 0, r = 0;  ///< centred coordinates
  };
  static constexpr int kMaxBins = 720;

  size_t gather(const std::vector<cv::Point2d>& edge);
  void order_by_angle(size_t n);
  bool best_hypothesis(size_t n, const BallFitParams& p, double hint, Circle& best) const;
  double score(const Circle& c, size_t n, const BallFitParams& p, double hint) const;
  size_t select_inliers(const Circle& c, size_t n, double tolerance);
  bool refine(Circle& c, size_t n, const BallFitParams& p);
  bool kasa(Circle& c, size_t m) const;
  bool gauss_newton(Circle& c, size_t m, int steps) const;
  BallFit describe(const Circle& c, size_t n, const BallFitParams& p);
  uint64_t arc_of(double r) const;  ///< BallFit::arc from sector_points_, filled by describe()

  size_t max_points_;
  cv::Point2d offset_;                              // mean of the points used
  std::vector<double> xs_, ys_;                     // centred points
  std::vector<float> xf_, yf_;                      // the same in float, for score()
  std::vector<std::pair<double, uint32_t>> order_;  // (pseudo-angle, index), sorted
  std::vector<uint32_t> inliers_;                   // indices of the current inliers
  std::array<uint8_t, kMaxBins> bins_{};
  std::array<uint16_t, kArcSectors> sector_points_{};
};

}  // namespace sg::vision
