#pragma once

/// Which region of the ball's colour is the ball: each candidate region gets a cost, a sum of
/// squared, scaled deviations from what a ball would show (lower is better; a candidate above
/// `max_cost` is not the ball). The terms:
///
///   shape:   0 for a region whose moments and extent already show a whole disc; else
///            (rms / fit_rms_scale)^2 of the circle fitted to its outline (a sphere images as a
///            near-circle), plus ((min_support - support) / 0.1)^2 when less of a circle than
///            `min_support` supports it (under half of min_support: not the ball), plus the
///            moments' axis ratio l / w (eq. 16-17) beyond `max_axis_ratio`, in ln units over
///            `axis_ratio_scale`, when the whole disc is seen;
///   size:    (ln(radius / expected) / size_scale)^2, the expected radius from the ball's depth
///            (stereo) or from its last image;
///   motion:  (|centre - expected| / sigma)^2, sigma = motion_scale x the ball's last diameter
///            x (1 + misses), around the predicted or last centre;
///   colour:  ((mean r - mu_r) / (colour_scale sigma_r))^2 + the same for g, against the colour
///            learned from confident detections (ColorModel);
///   clutter: `clutter_cost` when the region sits where a static region of the colour was learned
///            as background;
///   area:    largest_weight x ln(largest area / area): the paper's rule (section 5.2) as a weak
///            prior, which decides between regions nothing else tells apart.
///
///     ScoreContext context;  context.expected_centre = last;  context.expected_radius = 20;
///     const double cost = candidate_cost(candidate, context, ScoringParams{});
///     if (cost <= ScoringParams{}.max_cost) ...   // it may be the ball

#include <cmath>
#include <opencv2/core.hpp>
#include <optional>

#include "vision/ball_fit.hpp"
#include "vision/moments.hpp"

namespace sg::vision {

/// The weights of candidate_cost(): each a scale in the unit of its term.
struct ScoringParams {
  double fit_rms_scale = 0.8;      ///< px of radial residual of the outline's circle
  double min_support = 0.35;       ///< of the circumference: less is not a ball's outline
  double max_axis_ratio = 1.3;     ///< l / w a whole ball's image stays under
  double axis_ratio_scale = 0.15;  ///< ln units
  double size_scale = 0.25;        ///< ln units of radius
  double motion_scale = 1.5;       ///< ball diameters per frame
  double colour_scale = 4.0;       ///< learned standard deviations
  double clutter_cost = 16.0;      ///< added for a region on learned background
  double largest_weight = 0.5;     ///< per ln unit of area below the window's largest region
  double max_cost = 25.0;          ///< above: not the ball
  /// Above: not the ball when there is no track or the last frame missed it. Continuity lets a
  /// tracked ball be taken through a frame that looks little like one (a finger across it);
  /// a new track starts only from a region that looks like a ball on its own.
  double acquire_max_cost = 4.0;
  /// ... and only from a region whose outline shows at least this share of the circle (a whole
  /// disc passes): a sliver of red is no ball on its own, whatever its circle's cost.
  double acquire_min_support = 0.5;
  /// The ball's size is learned only from candidates whose circle this much of the outline
  /// supports (or a whole disc): a nearly hidden ball's fitted radius is too uncertain to keep.
  double size_min_support = 0.5;
  /// The fitted circle's centre replaces the centroid when less than this of its outline is seen
  /// (a whole disc's centroid is the more precise, 0.13 px against the fit's ~0.3 px).
  double fit_below_support = 0.9;
  /// Radius (px) above which a region is not fitted (a large red surface): it is not the ball.
  double max_radius = 120.0;
};

/// One region of the ball's colour with what scoring knows of it.
struct Candidate {
  Blob blob;                      ///< eq. 11-22 of the region
  cv::Point2d centre;             ///< the ball's centre: fitted circle or centroid
  double radius = 0;              ///< px: fitted, or sqrt(area / pi)
  double support = std::nan("");  ///< of the fitted circle's circumference (NaN: not fitted)
  double fit_rms = std::nan("");  ///< px
  bool fitted = false;            ///< centre is the fitted circle's
  /// The sectors of the outline the centre rests on (BallFit::arc); kWholeArc for a centroid.
  uint64_t arc = kWholeArc;
  /// The moments and the extent already show a whole disc (axis ratio, fill of its box, box
  /// aspect): no circle is fitted, centre is the centroid, support and fit_rms are NaN.
  bool whole_disc = false;
  bool too_large = false;  ///< larger than ScoringParams::max_radius: not fitted, not the ball
  double mean_r = 0, mean_g = 0;  ///< mean chromaticity (eq. 7)
  bool clutter = false;           ///< on learned background
  double cost = 0;                ///< candidate_cost()
};

/// What the ball is expected to look like in this frame.
struct ScoreContext {
  std::optional<cv::Point2d> expected_centre;  ///< predicted or last centre
  double motion_sigma = 0;                     ///< px, with expected_centre
  std::optional<double> expected_radius;       ///< px
  /// Learned colour: mean and standard deviation of r and g (absent until learned).
  std::optional<cv::Vec4d> colour;  ///< mu_r, sigma_r, mu_g, sigma_g
  double largest_area = 0;          ///< px, of the window's largest region
};

/// The candidate's cost (see the file's comment); infinite for a region that could not be the
/// ball at all (no finite centre or radius).
double candidate_cost(const Candidate& c, const ScoreContext& context, const ScoringParams& p);

}  // namespace sg::vision
