#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <vector>

#include "vision/camera_model.hpp"

namespace sg::vision {

/// A world point (robot frame, m) and where one camera sees it (px).
struct Correspondence {
  Eigen::Vector3d world;
  Eigen::Vector2d pixel;
};

/// Correspondences that cannot determine a camera; the message says which problem.
class CalibrationInputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A camera estimated by the DLT.
struct DltResult {
  Eigen::Matrix<double, 3, 4> P_linear;  ///< the linear estimate (eq. 5-6), scaled to ||P|| = 1
  Eigen::Matrix<double, 3, 4> P;         ///< after refinement of the reprojection error
  double rms_linear = 0;                 ///< RMS reprojection error of P_linear, px
  double rms = 0;                        ///< RMS reprojection error of P, px
  CameraModel camera;                    ///< P decomposed into K, R, t (no distortion)
};

/// The paper's camera calibration (section 4): P from n >= 6 correspondences by the direct linear
/// transform — two rows per point (eq. 5, 6), solved by SVD after Hartley's normalization of both
/// point sets — then refined by Levenberg-Marquardt on the reprojection error (never worse than
/// the linear estimate). Throws CalibrationInputError for fewer than 6 points, non-finite values,
/// repeated world points, all points on one plane, or a configuration that leaves P undetermined.
DltResult calibrate_dlt(const std::vector<Correspondence>& points, int image_width,
                        int image_height, bool refine = true);

/// RMS distance in pixels between the points' pixels and P's projections of their world points.
double reprojection_rms(const Eigen::Matrix<double, 3, 4>& P,
                        const std::vector<Correspondence>& points);

/// K, R, t of P = s K [R | t] (RQ decomposition; K with a positive diagonal and K(2,2) = 1,
/// R a rotation).
CameraModel decompose_projection(const Eigen::Matrix<double, 3, 4>& P, int image_width,
                                 int image_height);

}  // namespace sg::vision
