#include "vision/dlt.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace sg::vision {
namespace {

using Matrix34 = Eigen::Matrix<double, 3, 4>;

/// Hartley's normalization: centroid to the origin, mean distance sqrt(dim).
template <int D>
Eigen::Matrix<double, D + 1, D + 1> normalizing_transform(
    const std::vector<Eigen::Matrix<double, D, 1>>& points) {
  Eigen::Matrix<double, D, 1> mean = Eigen::Matrix<double, D, 1>::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  double distance = 0;
  for (const auto& p : points) distance += (p - mean).norm();
  distance /= static_cast<double>(points.size());
  const double s = std::sqrt(double(D)) / std::max(distance, 1e-12);
  Eigen::Matrix<double, D + 1, D + 1> T = Eigen::Matrix<double, D + 1, D + 1>::Identity() * s;
  T(D, D) = 1;
  T.template topRightCorner<D, 1>() = -s * mean;
  return T;
}

void check_input(const std::vector<Correspondence>& points) {
  if (points.size() < 6) {
    throw CalibrationInputError("DLT needs at least 6 points, got " +
                                std::to_string(points.size()));
  }
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].world.allFinite() || !points[i].pixel.allFinite())
      throw CalibrationInputError("point " + std::to_string(i + 1) +
                                  " has a non-finite coordinate");
    for (size_t j = 0; j < i; ++j) {
      if ((points[i].world - points[j].world).norm() < 1e-9)
        throw CalibrationInputError("points " + std::to_string(j + 1) + " and " +
                                    std::to_string(i + 1) + " are the same world point");
    }
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p.world;
  mean /= static_cast<double>(points.size());
  Eigen::MatrixXd centred(3, points.size());
  for (size_t i = 0; i < points.size(); ++i)
    centred.col(static_cast<Eigen::Index>(i)) = points[i].world - mean;
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::MatrixXd>(centred).singularValues();
  if (s[2] < 1e-6 * s[0]) {
    throw CalibrationInputError(
        "all points lie on one plane (or a line): the DLT needs points off a plane; for a flat "
        "target use the checkerboard method");
  }
}

/// Reprojection residuals (u, v per point) of P on normalized points, and their Jacobian with
/// respect to the 12 entries of P (row-major): u = a/c, du/dP1 = X/c, du/dP3 = -u X/c.
void residuals(const Matrix34& P, const std::vector<Eigen::Vector4d>& X,
               const std::vector<Eigen::Vector2d>& x, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
  const Eigen::Index n = static_cast<Eigen::Index>(X.size());
  r.resize(2 * n);
  if (J) J->setZero(2 * n, 12);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d w = P * X[static_cast<size_t>(i)];
    const double u = w.x() / w.z(), v = w.y() / w.z();
    r[2 * i] = u - x[static_cast<size_t>(i)].x();
    r[2 * i + 1] = v - x[static_cast<size_t>(i)].y();
    if (J) {
      const Eigen::RowVector4d Xc = X[static_cast<size_t>(i)].transpose() / w.z();
      J->block<1, 4>(2 * i, 0) = Xc;
      J->block<1, 4>(2 * i, 8) = -u * Xc;
      J->block<1, 4>(2 * i + 1, 4) = Xc;
      J->block<1, 4>(2 * i + 1, 8) = -v * Xc;
    }
  }
}

Eigen::Matrix<double, 12, 1> flat(const Matrix34& P) {
  Eigen::Matrix<double, 12, 1> p;
  for (int i = 0; i < 3; ++i) p.segment<4>(4 * i) = P.row(i).transpose();
  return p;
}
Matrix34 unflat(const Eigen::Matrix<double, 12, 1>& p) {
  Matrix34 P;
  for (int i = 0; i < 3; ++i) P.row(i) = p.segment<4>(4 * i).transpose();
  return P / P.norm();
}

/// Levenberg-Marquardt on the normalized reprojection error; the scale of P is its gauge.
Matrix34 refine(Matrix34 P, const std::vector<Eigen::Vector4d>& X,
                const std::vector<Eigen::Vector2d>& x) {
  Eigen::VectorXd r, r_new;
  Eigen::MatrixXd J;
  residuals(P, X, x, r, &J);
  double cost = r.squaredNorm(), lambda = 1e-3;
  for (int iteration = 0; iteration < 200; ++iteration) {
    const Eigen::Matrix<double, 12, 12> H = J.transpose() * J;
    const Eigen::Matrix<double, 12, 1> g = J.transpose() * r;
    Eigen::Matrix<double, 12, 12> A = H;
    A.diagonal() += lambda * (H.diagonal().array() + 1e-12).matrix();
    const Eigen::Matrix<double, 12, 1> step = A.ldlt().solve(-g);
    const Matrix34 candidate = unflat(flat(P) + step);
    residuals(candidate, X, x, r_new, nullptr);
    const double new_cost = r_new.squaredNorm();
    if (new_cost < cost) {
      const bool converged = cost - new_cost < 1e-15 * cost + 1e-30;
      P = candidate;
      cost = new_cost;
      lambda = std::max(lambda / 10, 1e-12);
      residuals(P, X, x, r, &J);
      if (converged) break;
    } else {
      lambda *= 10;
      if (lambda > 1e12) break;
    }
  }
  return P;
}

}  // namespace

double reprojection_rms(const Matrix34& P, const std::vector<Correspondence>& points) {
  double sum = 0;
  for (const auto& c : points) {
    const Eigen::Vector3d w = P * c.world.homogeneous();
    sum += (w.hnormalized() - c.pixel).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(points.size()));
}

CameraModel decompose_projection(const Matrix34& P_in, int width, int height) {
  Matrix34 P = P_in;
  if (P.leftCols<3>().determinant() < 0) P = -P;  // so that R is a rotation and points are in front
  const Eigen::Matrix3d M = P.leftCols<3>();
  // RQ of M from the QR of the row-reversed transpose: M = K R.
  Eigen::Matrix3d flip;
  flip << 0, 0, 1, 0, 1, 0, 1, 0, 0;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((flip * M).transpose());
  const Eigen::Matrix3d Q = qr.householderQ();
  const Eigen::Matrix3d Rq = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d K = flip * Rq.transpose() * flip;
  Eigen::Matrix3d R = flip * Q.transpose();
  const Eigen::Vector3d signs = K.diagonal().array().sign();
  K = K * signs.asDiagonal();
  R = signs.asDiagonal() * R;
  if (R.determinant() < 0) throw CalibrationInputError("P does not decompose into a rotation");
  const Eigen::Vector3d t = K.inverse() * P.col(3);
  K /= K(2, 2);
  return CameraModel(width, height, {K(0, 0), K(1, 1), K(0, 2), K(1, 2), K(0, 1)}, {}, R, t);
}

DltResult calibrate_dlt(const std::vector<Correspondence>& points, int width, int height,
                        bool do_refine) {
  check_input(points);
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& c : points) world.push_back(c.world), pixels.push_back(c.pixel);
  const Eigen::Matrix4d Tw = normalizing_transform<3>(world);
  const Eigen::Matrix3d Ti = normalizing_transform<2>(pixels);
  std::vector<Eigen::Vector4d> X;
  std::vector<Eigen::Vector2d> x;
  for (size_t i = 0; i < points.size(); ++i) {
    X.push_back(Tw * world[i].homogeneous());
    x.push_back((Ti * pixels[i].homogeneous()).hnormalized());
  }
  // Eq. 5 and 6 for every point: A p = 0 with p the 12 entries of P (row-major).
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * static_cast<Eigen::Index>(points.size()), 12);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Index r = 2 * static_cast<Eigen::Index>(i);
    A.block<1, 4>(r, 0) = X[i].transpose();
    A.block<1, 4>(r, 8) = -x[i].x() * X[i].transpose();
    A.block<1, 4>(r + 1, 4) = X[i].transpose();
    A.block<1, 4>(r + 1, 8) = -x[i].y() * X[i].transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  if (s[10] < 1e-9 * s[0]) {
    throw CalibrationInputError("the points do not determine P (a singular configuration)");
  }
  const Matrix34 P_normalized = unflat(svd.matrixV().col(11));
  DltResult result;
  auto denormalize = [&](const Matrix34& Pn) {
    const Matrix34 P = Ti.inverse() * Pn * Tw;
    return Matrix34(P / P.norm());
  };
  result.P_linear = denormalize(P_normalized);
  result.rms_linear = reprojection_rms(result.P_linear, points);
  result.P = do_refine ? denormalize(refine(P_normalized, X, x)) : result.P_linear;
  result.rms = reprojection_rms(result.P, points);
  if (result.rms > result.rms_linear) {  // refinement never makes it worse
    result.P = result.P_linear;
    result.rms = result.rms_linear;
  }
  result.camera = decompose_projection(result.P, width, height);
  return result;
}

}  // namespace sg::vision
