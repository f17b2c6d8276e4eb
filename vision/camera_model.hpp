#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace sg::vision {

/// Focal lengths, principal point and skew, pixels: K = [fx skew cx; 0 fy cy; 0 0 1]. Skew is 0
/// for real cameras and in OpenCV's model; a DLT estimate keeps its own so that K [R|t] is its P.
struct Intrinsics {
  double fx = 560.0;
  double fy = 560.0;
  double cx = 319.5;
  double cy = 239.5;
  double skew = 0.0;
};

/// OpenCV's lens distortion model (k1, k2, p1, p2, k3), on normalized coordinates:
///   x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)
///   y_d = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  bool is_zero() const { return k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0; }
};

/// A calibrated camera: the paper's pinhole model w = P W (eq. 1-4) with P = K [R | t], plus
/// lens distortion. R, t take a point from the world (robot base) frame to the camera frame
/// (x right, y down, z along the optical axis).
///
///     auto cam = CameraModel::look_at(640, 480, {560, 560, 319.5, 239.5}, {},
///                                     /*eye=*/{0.8, -0.25, 0.4}, /*target=*/{0.45, 0, 0.1});
///     if (auto px = cam.project({0.45, 0.0, 0.1})) { ... }   // pixel (u, v)
class CameraModel {
 public:
  CameraModel() = default;
  CameraModel(int width, int height, const Intrinsics& intrinsics, const Distortion& distortion,
              const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

  /// A camera at `eye` whose optical axis passes through `target`, image "up" toward `up`.
  static CameraModel look_at(int width, int height, const Intrinsics& intrinsics,
                             const Distortion& distortion, const Eigen::Vector3d& eye,
                             const Eigen::Vector3d& target,
                             const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

  int width() const { return width_; }
  int height() const { return height_; }
  const Intrinsics& intrinsics() const { return intrinsics_; }
  const Distortion& distortion() const { return distortion_; }
  const Eigen::Matrix3d& R() const { return R_; }
  const Eigen::Vector3d& t() const { return t_; }

  /// The 3x3 intrinsic matrix K.
  Eigen::Matrix3d K() const;
  /// The 3x4 camera matrix P = K [R | t] of eq. 1-2 (distortion not included).
  Eigen::Matrix<double, 3, 4> P() const;
  /// The camera centre in the world frame, -R^T t.
  Eigen::Vector3d centre() const { return -R_.transpose() * t_; }

  /// A world point in the camera frame.
  Eigen::Vector3d to_camera(const Eigen::Vector3d& world) const { return R_ * world + t_; }

  /// Pixel of a world point; nullopt when it is not in front of the camera (z <= 0).
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& world) const;
  /// Pixel of a camera-frame point with z > 0.
  Eigen::Vector2d project_camera(const Eigen::Vector3d& camera_point) const;

  /// Applies the lens distortion to normalized coordinates (x/z, y/z).
  Eigen::Vector2d distort(const Eigen::Vector2d& normalized) const;
  /// Inverts distort() by fixed-point iteration (as cv::undistortPoints does).
  Eigen::Vector2d undistort(const Eigen::Vector2d& distorted) const;

  /// Unit direction, in the camera frame, of the ray through a pixel.
  Eigen::Vector3d ray_camera(const Eigen::Vector2d& pixel) const;

 private:
  int width_ = 0;
  int height_ = 0;
  Intrinsics intrinsics_;
  Distortion distortion_;
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
};

}  // namespace sg::vision
