#include "vision/triangulation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sg::vision {
namespace {

/// The pixel an ideal (distortion-free) camera with the same K would have seen.
Eigen::Vector2d ideal_pixel(const CameraModel& cam, const Eigen::Vector2d& pixel) {
  if (cam.distortion().is_zero()) return pixel;
  const Eigen::Vector3d ray = cam.ray_camera(pixel);
  return (cam.K() * (ray / ray.z())).head<2>();
}

using Cameras = std::vector<const CameraModel*>;
using Pixels = std::vector<Eigen::Vector2d>;

/// Throws unless there is one finite pixel for each of at least two cameras.
void check_views(const Cameras& cameras, const Pixels& pixels) {
  if (cameras.size() < 2 || cameras.size() != pixels.size())
    throw std::invalid_argument("triangulate: needs one pixel for each of at least two cameras");
  for (const auto& p : pixels) {
    if (!p.allFinite()) throw std::invalid_argument("triangulate: a pixel is not finite");
  }
}

/// The homogeneous linear solution: the rows x P3 - P1 and y P3 - P2 of eq. 24-25 for every
/// camera (on undistorted pixels, each row scaled by |P3's first three|), stacked as A X = 0 and
/// solved by SVD (X the right singular vector of the smallest singular value).
Eigen::Vector3d linear_solution(const Cameras& cameras, const Pixels& pixels) {
  const Eigen::Index n = static_cast<Eigen::Index>(cameras.size());
  Eigen::MatrixXd A(2 * n, 4);
  for (Eigen::Index i = 0; i < n; ++i) {  // x P3 - P1 and y P3 - P2 (eq. 24, 25), homogeneous
    const CameraModel& cam = *cameras[static_cast<size_t>(i)];
    const Eigen::Matrix<double, 3, 4> P = cam.P();
    const Eigen::Vector2d x = ideal_pixel(cam, pixels[static_cast<size_t>(i)]);
    A.row(2 * i) = (x.x() * P.row(2) - P.row(0)) / P.row(2).head<3>().norm();
    A.row(2 * i + 1) = (x.y() * P.row(2) - P.row(1)) / P.row(2).head<3>().norm();
  }
  const Eigen::Vector4d X =
      Eigen::JacobiSVD<Eigen::MatrixXd>(A, Eigen::ComputeFullV).matrixV().col(3);
  return X.hnormalized();
}

/// r = projection of `point` through each camera's full model minus its pixel (2 rows a camera);
/// a point behind (or on) a camera's plane projects to (1e6, 1e6).
void residual(const Cameras& cameras, const Pixels& pixels, const Eigen::Vector3d& point,
              Eigen::VectorXd& r) {
  const Eigen::Index n = static_cast<Eigen::Index>(cameras.size());
  r.resize(2 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d c = cameras[static_cast<size_t>(i)]->to_camera(point);
    const Eigen::Vector2d p = c.z() > 1e-9 ? cameras[static_cast<size_t>(i)]->project_camera(c)
                                           : Eigen::Vector2d(1e6, 1e6);
    r.segment<2>(2 * i) = p - pixels[static_cast<size_t>(i)];
  }
}

/// The residual's Jacobian d r / d point by central differences, steps 1e-7 max(1, |point|).
Eigen::MatrixXd jacobian(const Cameras& cameras, const Pixels& pixels,
                         const Eigen::Vector3d& point) {
  Eigen::MatrixXd J(2 * static_cast<Eigen::Index>(cameras.size()), 3);
  Eigen::VectorXd plus, minus;
  for (int k = 0; k < 3; ++k) {
    const double h = 1e-7 * std::max(1.0, point.norm());
    Eigen::Vector3d a = point, b = point;
    a[k] += h, b[k] -= h;
    residual(cameras, pixels, a, plus);
    residual(cameras, pixels, b, minus);
    J.col(k) = (plus - minus) / (2 * h);
  }
  return J;
}

/// Gauss-Newton on the reprojection error from `position` (residual `r`): at most 20 steps
/// (J^T J) step = -J^T r, each kept only if it lowers |r|^2; stops on a step under 1e-12 m.
void refine(const Cameras& cameras, const Pixels& pixels, Eigen::Vector3d& position,
            Eigen::VectorXd& r) {
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Eigen::MatrixXd J = jacobian(cameras, pixels, position);
    const Eigen::Vector3d step = (J.transpose() * J).ldlt().solve(-J.transpose() * r);
    Eigen::VectorXd r_new;
    residual(cameras, pixels, position + step, r_new);
    if (!(r_new.squaredNorm() < r.squaredNorm())) break;
    position += step;
    r = r_new;
    if (step.norm() < 1e-12) break;
  }
}

/// The widest angle between the rays from any two camera centres to `position`; sets
/// `behind_camera` if the point is not in front of every camera.
double widest_ray_angle(const Cameras& cameras, const Eigen::Vector3d& position,
                        bool& behind_camera) {
  const Eigen::Index n = static_cast<Eigen::Index>(cameras.size());
  double widest = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d ci = cameras[static_cast<size_t>(i)]->to_camera(position);
    if (!(ci.z() > 0)) behind_camera = true;
    const Eigen::Vector3d ri = (position - cameras[static_cast<size_t>(i)]->centre()).normalized();
    for (Eigen::Index j = 0; j < i; ++j) {
      const Eigen::Vector3d rj =
          (position - cameras[static_cast<size_t>(j)]->centre()).normalized();
      widest = std::max(widest, std::acos(std::clamp(ri.dot(rj), -1.0, 1.0)));
    }
  }
  return widest;
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

Triangulated triangulate(const std::vector<const CameraModel*>& cameras,
                         const std::vector<Eigen::Vector2d>& pixels,
                         const TriangulationOptions& o) {
  check_views(cameras, pixels);
  Triangulated t;
  t.position = linear_solution(cameras, pixels);
  Eigen::VectorXd r;
  residual(cameras, pixels, t.position, r);
  if (o.refine) refine(cameras, pixels, t.position, r);
  t.reprojection_error = std::sqrt(r.squaredNorm() / static_cast<double>(cameras.size()));
  const Eigen::MatrixXd J = jacobian(cameras, pixels, t.position);
  const Eigen::Matrix3d information = J.transpose() * J;  // sigma: sqrt(diag((J^T J)^-1)) sigma_px
  if (information.determinant() > 0) {
    t.sigma = (information.inverse().diagonal().array().sqrt() * o.pixel_sigma).matrix();
  }
  t.near_parallel = widest_ray_angle(cameras, t.position, t.behind_camera) < o.min_ray_angle;
  return t;
}

}  // namespace sg::vision
