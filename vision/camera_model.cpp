#include "vision/camera_model.hpp"

#include <stdexcept>

namespace sg::vision {

CameraModel::CameraModel(int width, int height, const Intrinsics& intrinsics,
                         const Distortion& distortion, const Eigen::Matrix3d& R,
                         const Eigen::Vector3d& t)
    : width_(width),
      height_(height),
      intrinsics_(intrinsics),
      distortion_(distortion),
      R_(R),
      t_(t) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("camera image size must be positive");
  if (!(intrinsics.fx > 0) || !(intrinsics.fy > 0))
    throw std::invalid_argument("camera focal lengths must be positive");
}

CameraModel CameraModel::look_at(int width, int height, const Intrinsics& intrinsics,
                                 const Distortion& distortion, const Eigen::Vector3d& eye,
                                 const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - eye).normalized();  // optical axis
  const Eigen::Vector3d x = z.cross(up).normalized();     // image right
  if (!x.allFinite()) throw std::invalid_argument("look_at: the optical axis is parallel to up");
  const Eigen::Vector3d y = z.cross(x);  // image down
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  return CameraModel(width, height, intrinsics, distortion, R, -R * eye);
}

Eigen::Matrix3d CameraModel::K() const {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  K(0, 0) = intrinsics_.fx;
  K(1, 1) = intrinsics_.fy;
  K(0, 1) = intrinsics_.skew;
  K(0, 2) = intrinsics_.cx;
  K(1, 2) = intrinsics_.cy;
  return K;
}

Eigen::Matrix<double, 3, 4> CameraModel::P() const {
  Eigen::Matrix<double, 3, 4> Rt;
  Rt << R_, t_;
  return K() * Rt;
}

std::optional<Eigen::Vector2d> CameraModel::project(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d c = to_camera(world);
  if (!(c.z() > 0)) return std::nullopt;
  return project_camera(c);
}

Eigen::Vector2d CameraModel::project_camera(const Eigen::Vector3d& c) const {
  const Eigen::Vector2d d = distort({c.x() / c.z(), c.y() / c.z()});
  return {intrinsics_.fx * d.x() + intrinsics_.skew * d.y() + intrinsics_.cx,
          intrinsics_.fy * d.y() + intrinsics_.cy};
}

Eigen::Vector2d CameraModel::distort(const Eigen::Vector2d& n) const {
  if (distortion_.is_zero()) return n;
  const Distortion& k = distortion_;
  const double x = n.x(), y = n.y(), r2 = x * x + y * y;
  const double radial = 1 + r2 * (k.k1 + r2 * (k.k2 + r2 * k.k3));
  return {x * radial + 2 * k.p1 * x * y + k.p2 * (r2 + 2 * x * x),
          y * radial + k.p1 * (r2 + 2 * y * y) + 2 * k.p2 * x * y};
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& d) const {
  if (distortion_.is_zero()) return d;
  Eigen::Vector2d n = d;
  for (int i = 0; i < 20; ++i) n += d - distort(n);  // converges for moderate distortion
  return n;
}

Eigen::Vector3d CameraModel::ray_camera(const Eigen::Vector2d& pixel) const {
  const double y = (pixel.y() - intrinsics_.cy) / intrinsics_.fy;
  const Eigen::Vector2d d{(pixel.x() - intrinsics_.cx - intrinsics_.skew * y) / intrinsics_.fx, y};
  const Eigen::Vector2d n = undistort(d);
  return Eigen::Vector3d(n.x(), n.y(), 1.0).normalized();
}

}  // namespace sg::vision
