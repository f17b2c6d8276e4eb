#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "vision/camera_model.hpp"

namespace sg::vision {

/// A triangulated point and how well it fits its observations.
struct Triangulated {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< robot frame, m
  double reprojection_error = 0;                       ///< RMS over the views, pixels
  bool behind_camera = false;  ///< the point is not in front of every camera
  bool near_parallel = false;  ///< the rays meet at less than the angle asked for
  Eigen::Vector3d sigma = Eigen::Vector3d::Constant(std::nan(""));  ///< 1-sigma per axis, m
};

/// The paper's linear triangulation (section 5.4, eq. 23-26): the least-squares solution of the
/// four equations x P3^T W = P1^T W, y P3^T W = P2^T W of both cameras, A X = B. Pixels are first
/// undistorted with each camera's lens model, so P = K [R|t] applies.
Triangulated triangulate_linear(const CameraModel& left, const Eigen::Vector2d& left_pixel,
                                const CameraModel& right, const Eigen::Vector2d& right_pixel);

/// Options for triangulate().
struct TriangulationOptions {
  bool refine = true;        ///< minimize the reprojection error after the linear step
  double pixel_sigma = 0.3;  ///< assumed image noise (px), for the position's sigma
  double min_ray_angle = 1.0 * M_PI / 180;  ///< below this the rays are "nearly parallel"
};

/// N >= 2 views: the homogeneous linear solution (SVD of the stacked eq. 24-25 rows, on
/// undistorted pixels), then Gauss-Newton on the reprojection error through each camera's full
/// model, with the position's uncertainty from the residual Jacobian and `pixel_sigma`.
Triangulated triangulate(const std::vector<const CameraModel*>& cameras,
                         const std::vector<Eigen::Vector2d>& pixels,
                         const TriangulationOptions& options = {});

}  // namespace sg::vision
