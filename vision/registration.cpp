#include "vision/registration.hpp"

#include <Eigen/Dense>

#include "vision/dlt.hpp"

namespace sg::vision {

RigidFit fit_rigid(const std::vector<Eigen::Vector3d>& from,
                   const std::vector<Eigen::Vector3d>& to) {
  if (from.size() != to.size()) throw CalibrationInputError("registration: point counts differ");
  if (from.size() < 4) {
    throw CalibrationInputError("registration needs at least 4 points, got " +
                                std::to_string(from.size()));
  }
  const Eigen::Index n = static_cast<Eigen::Index>(from.size());
  Eigen::Matrix3Xd a(3, n), b(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!from[static_cast<size_t>(i)].allFinite() || !to[static_cast<size_t>(i)].allFinite())
      throw CalibrationInputError("registration: point " + std::to_string(i + 1) +
                                  " is not finite");
    a.col(i) = from[static_cast<size_t>(i)];
    b.col(i) = to[static_cast<size_t>(i)];
  }
  const Eigen::Vector3d s =
      Eigen::JacobiSVD<Eigen::MatrixXd>(a.colwise() - a.rowwise().mean()).singularValues();
  if (s[1] < 1e-6 * s[0]) throw CalibrationInputError("registration: the points lie on one line");
  RigidFit fit;
  fit.transform.matrix() = Eigen::umeyama(a, b, false);
  fit.rms = std::sqrt(((fit.transform * a) - b).colwise().squaredNorm().mean());
  return fit;
}

StereoCalibration change_world_frame(const StereoCalibration& c, const Eigen::Isometry3d& T) {
  auto move = [&](const CameraModel& cam) {
    // x_cam = R X_old + t and X_old = T X_new, so x_cam = (R T_R) X_new + (R T_t + t).
    return CameraModel(cam.width(), cam.height(), cam.intrinsics(), cam.distortion(),
                       cam.R() * T.linear(), cam.R() * T.translation() + cam.t());
  };
  StereoCalibration out = c;
  out.left = move(c.left);
  out.right = move(c.right);
  return out;
}

}  // namespace sg::vision
