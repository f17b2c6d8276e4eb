#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "vision/calibration_file.hpp"

namespace sg::vision {

/// A rigid motion (rotation and translation, no scale) and how well it fits.
struct RigidFit {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  ///< takes `from` points to `to`
  double rms = 0;  ///< RMS distance between transformed `from` and `to`, m
};

/// The least-squares rigid motion taking `from` to `to` (Umeyama's method, Eigen::umeyama without
/// scale). Needs at least 4 pairs of finite points, not all on one line; throws
/// CalibrationInputError otherwise.
RigidFit fit_rigid(const std::vector<Eigen::Vector3d>& from,
                   const std::vector<Eigen::Vector3d>& to);

/// The same calibration with its world frame moved: `world_from_new` takes points of the new
/// frame (the robot's) into the calibration's current world frame (the left camera's).
StereoCalibration change_world_frame(const StereoCalibration& calibration,
                                     const Eigen::Isometry3d& world_from_new);

}  // namespace sg::vision
