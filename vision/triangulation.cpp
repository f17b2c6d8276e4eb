#include "vision/triangulation.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace sg::vision {
namespace {

/// The pixel an ideal (distortion-free) camera with the same K would have seen.
Eigen::Vector2d ideal_pixel(const CameraModel& cam, const Eigen::Vector2d& pixel) {
  if (cam.distortion().is_zero()) return pixel;
  const Eigen::Vector3d ray = cam.ray_camera(pixel);
  return (cam.K() * (ray / ray.z())).head<2>();
}

}  // namespace

Triangulated triangulate_linear(const CameraModel& left, const Eigen::Vector2d& left_pixel,
                                const CameraModel& right, const Eigen::Vector2d& right_pixel) {
  Eigen::Matrix<double, 4, 3> A;
  Eigen::Vector4d B;
  int row = 0;
  for (const auto& [cam, pixel] : {std::pair{&left, ideal_pixel(left, left_pixel)},
                                   std::pair{&right, ideal_pixel(right, right_pixel)}}) {
    const Eigen::Matrix<double, 3, 4> P = cam->P();
    for (int i = 0; i < 2; ++i, ++row) {  // eq. 26: (P_i,1..3 - x P_3,1..3) X = x P_34 - P_i4
      const double coordinate = pixel[i];
      A.row(row) = P.block<1, 3>(i, 0) - coordinate * P.block<1, 3>(2, 0);
      B[row] = coordinate * P(2, 3) - P(i, 3);
    }
  }
  Triangulated t;
  t.position = A.colPivHouseholderQr().solve(B);
  double sum = 0;
  for (const auto& [cam, pixel] : {std::pair{&left, left_pixel}, std::pair{&right, right_pixel}}) {
    const auto projected = cam->project(t.position);
    if (!projected) {
      t.behind_camera = true;
      continue;
    }
    sum += (*projected - pixel).squaredNorm();
  }
  t.reprojection_error = std::sqrt(sum / 2);
  return t;
}

}  // namespace sg::vision
