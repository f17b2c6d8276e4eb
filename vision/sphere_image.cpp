#include "vision/sphere_image.hpp"

#include <algorithm>
#include <cmath>

namespace sg::vision {

namespace {

/// The ray bisecting the silhouette rays through c -+ a u (see the header).
Eigen::Vector3d bisector(const CameraModel& camera, const Eigen::Vector2d& c,
                         const Eigen::Vector2d& u, double a, double& alpha) {
  const Eigen::Vector3d d1 = camera.ray_camera(c - a * u), d2 = camera.ray_camera(c + a * u);
  alpha = std::acos(std::clamp(d1.dot(d2), -1.0, 1.0)) / 2;
  return (d1 + d2).normalized();
}

}  // namespace

Eigen::Vector2d sphere_centre_pixel(const CameraModel& camera, const Eigen::Vector2d& apparent,
                                    double radius_px) {
  if (!(radius_px > 0) || !std::isfinite(radius_px) || !apparent.allFinite()) return apparent;
  const Intrinsics& k = camera.intrinsics();
  const Eigen::Vector2d out = apparent - Eigen::Vector2d(k.cx, k.cy);
  const double n = out.norm();
  if (n < 1e-6) return apparent;
  const Eigen::Vector2d u = out / n;
  // The radius seen is sqrt(a b); a / b = cos(alpha) / sqrt(cos^2 theta - sin^2 alpha) follows
  // from the estimate, which moves it little: three rounds settle it.
  double a = radius_px, alpha = 0;
  Eigen::Vector3d d = bisector(camera, apparent, u, a, alpha);
  for (int round = 0; round < 3; ++round) {
    const double cos_theta = d.z(), sin_alpha = std::sin(alpha);
    const double q = cos_theta * cos_theta - sin_alpha * sin_alpha;
    if (!(q > 1e-9)) return apparent;
    a = radius_px * std::sqrt(std::cos(alpha) / std::sqrt(q));
    d = bisector(camera, apparent, u, a, alpha);
  }
  if (!(d.z() > 1e-9) || !d.allFinite()) return apparent;
  return camera.project_camera(d);
}

}  // namespace sg::vision
