#pragma once

#include <Eigen/Core>

#include "vision/camera_model.hpp"

namespace sg::vision {

/// A triangulated point and how well it fits its observations.
struct Triangulated {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< robot frame, m
  double reprojection_error = 0;                       ///< RMS over both views, pixels
  bool behind_camera = false;  ///< the point is not in front of both cameras
};

/// The paper's linear triangulation (section 5.4, eq. 23-26): the least-squares solution of the
/// four equations x P3^T W = P1^T W, y P3^T W = P2^T W of both cameras, A X = B. Pixels are first
/// undistorted with each camera's lens model, so P = K [R|t] applies. The calibration issue
/// extends this (N views, iterative refinement, error estimates).
Triangulated triangulate_linear(const CameraModel& left, const Eigen::Vector2d& left_pixel,
                                const CameraModel& right, const Eigen::Vector2d& right_pixel);

}  // namespace sg::vision
