#pragma once

/// Which left and which right candidate are the ball: the pair that agrees with the cameras'
/// geometry. A true pair's centres lie on corresponding epipolar lines, so their linear
/// triangulation (eq. 26) reprojects within a pixel or so; and the point they give, at distance
/// D from each camera, must be where a sphere of the ball's radius R images with the radii seen,
/// f R / sqrt(D^2 - R^2). A red object on a far wall, or a pair of two different objects, fails
/// one or the other. The pair's cost adds both cameras' candidate costs (ball_score.hpp):
///
///   cost = cost_left + cost_right + (e / epipolar_sigma)^2
///          + sum over cameras (ln(r_seen / r_expected) / size_scale)^2
///
/// with e the triangulation's RMS reprojection error.
///
///     const StereoMatch m = match_stereo(left_detection, right_detection, calibration, {});
///     if (m.found()) { left.accept(left_detection, m.left); right.accept(right_detection,
///     m.right); }

#include <Eigen/Core>
#include <limits>

#include "vision/blob_tracker.hpp"
#include "vision/calibration_file.hpp"

namespace sg::vision {

struct StereoMatchParams {
  double ball_radius = 0.035;   ///< m; 0: unknown, no size term
  double epipolar_sigma = 1.5;  ///< px of reprojection error of a true pair
  double size_scale = 0.2;      ///< ln units of radius
  double max_cost = 40.0;       ///< above: no pair is the ball
};

struct StereoMatch {
  int left = -1, right = -1;  ///< candidate indices (-1: none)
  double cost = std::numeric_limits<double>::infinity();
  Eigen::Vector3d position = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool found() const { return left >= 0 && right >= 0; }
};

/// The radius (px) of the image of a sphere of `radius` m centred at `world`, f R / sqrt(D^2 -
/// R^2) with f the mean focal length; NaN when it is not in front of the camera.
double apparent_radius(const CameraModel& camera, const Eigen::Vector3d& world, double radius);

/// The lowest-cost pair of candidates whose costs are each within their tracker's max_cost and
/// whose pair cost is within p.max_cost.
StereoMatch match_stereo(const Detection& left, const Detection& right,
                         const StereoCalibration& calibration, const ScoringParams& scoring,
                         const StereoMatchParams& p);

}  // namespace sg::vision
