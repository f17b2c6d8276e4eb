#include "vision/checkerboard.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "vision/dlt.hpp"

namespace sg::vision {
namespace {

bool find_corners(const std::string& path, const CheckerboardParams& p, cv::Size& size,
                  std::vector<cv::Point2f>& corners) {
  const cv::Mat gray = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (gray.empty()) throw CalibrationInputError(path + ": cannot read the image");
  if (size.area() == 0) size = gray.size();
  if (gray.size() != size) {
    throw CalibrationInputError(path + ": " + std::to_string(gray.cols) + "x" +
                                std::to_string(gray.rows) + " differs from the first image's " +
                                std::to_string(size.width) + "x" + std::to_string(size.height));
  }
  if (!cv::findChessboardCorners(gray, p.pattern, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    return false;
  }
  cv::cornerSubPix(gray, corners, {11, 11}, {-1, -1},
                   {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.01});
  return true;
}

double view_rms(const std::vector<cv::Point3f>& board, const std::vector<cv::Point2f>& corners,
                const cv::Mat& rvec, const cv::Mat& tvec, const cv::Mat& K, const cv::Mat& D) {
  std::vector<cv::Point2f> projected;
  cv::projectPoints(board, rvec, tvec, K, D, projected);
  return cv::norm(corners, projected, cv::NORM_L2) / std::sqrt(double(corners.size()));
}

CameraModel to_camera(const cv::Mat& K, const cv::Mat& D, const cv::Mat& R, const cv::Mat& T,
                      cv::Size size) {
  Eigen::Matrix3d R_e;
  Eigen::Vector3d t_e;
  cv::cv2eigen(R, R_e);
  cv::cv2eigen(T, t_e);
  const cv::Mat d = D.reshape(1, 1);
  return CameraModel(
      size.width, size.height,
      {K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2)},
      {d.at<double>(0), d.at<double>(1), d.at<double>(2), d.at<double>(3), d.at<double>(4)}, R_e,
      t_e);
}

/// Throws unless the lists pair up and the pattern has at least 2x2 inner corners and a square.
void check_inputs(const std::vector<std::string>& left, const std::vector<std::string>& right,
                  const CheckerboardParams& p) {
  if (left.size() != right.size()) {
    throw CalibrationInputError(std::to_string(left.size()) + " left images but " +
                                std::to_string(right.size()) + " right images");
  }
  if (p.pattern.width < 2 || p.pattern.height < 2 || !(p.square > 0))
    throw CalibrationInputError(
        "the pattern needs at least 2x2 inner corners and a positive square");
}

/// The board's inner corners in its own plane (Z = 0), row by row, metres.
std::vector<cv::Point3f> board_points(const CheckerboardParams& p) {
  std::vector<cv::Point3f> board;
  for (int y = 0; y < p.pattern.height; ++y) {
    for (int x = 0; x < p.pattern.width; ++x) {
      board.emplace_back(static_cast<float>(x * p.square), static_cast<float>(y * p.square), 0.0f);
    }
  }
  return board;
}

/// The corners found in the stereo views where both images show the board.
struct Detections {
  cv::Size size;                                     ///< the images' size
  std::vector<std::vector<cv::Point2f>> corners[2];  ///< per camera, per used view
  std::vector<size_t> used;                          ///< the used views' indices in `views`
};

/// Why a view was dropped, from which of its images lacked the board.
std::string dropped_because(bool found_left, bool found_right) {
  const char* which = !found_left && !found_right ? "left and right images"
                      : !found_left               ? "left image"
                                                  : "right image";
  return std::string("board not found in the ") + which;
}

/// Looks for the board in every stereo view (calling `progress` with each image's name); a view
/// report per pair goes to `views`.
Detections find_boards(const std::vector<std::string>& left, const std::vector<std::string>& right,
                       const CheckerboardParams& p,
                       const std::function<void(const std::string&)>& progress,
                       std::vector<ViewReport>& views) {
  Detections d;
  for (size_t i = 0; i < left.size(); ++i) {
    ViewReport view;
    view.left = left[i];
    view.right = right[i];
    std::vector<cv::Point2f> l, r;
    if (progress) progress(left[i]);
    const bool found_left = find_corners(left[i], p, d.size, l);
    if (progress) progress(right[i]);
    const bool found_right = find_corners(right[i], p, d.size, r);
    if (found_left && found_right) {
      view.used = true;
      d.corners[0].push_back(l);
      d.corners[1].push_back(r);
      d.used.push_back(views.size());
    } else {
      view.dropped_because = dropped_because(found_left, found_right);
    }
    views.push_back(view);
  }
  return d;
}

/// Throws unless the board was found in at least 3 stereo views.
void require_three_views(const CheckerboardParams& p, size_t found) {
  if (found < 3) {
    throw CalibrationInputError("the " + std::to_string(p.pattern.width) + "x" +
                                std::to_string(p.pattern.height) + " board was found in " +
                                std::to_string(found) +
                                " stereo pairs; at least 3 are needed (wrong --pattern?)");
  }
}

/// Each camera's own calibration (K, D with k3 fixed at 0) from the used views; returns its RMS
/// reprojection error and writes each view's into `views`.
double calibrate_one(int c, const std::vector<cv::Point3f>& board,
                     const std::vector<std::vector<cv::Point3f>>& boards, const Detections& d,
                     cv::Mat& K, cv::Mat& D, std::vector<ViewReport>& views) {
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms =
      cv::calibrateCamera(boards, d.corners[c], d.size, K, D, rvecs, tvecs, cv::CALIB_FIX_K3);
  for (size_t v = 0; v < d.used.size(); ++v) {
    const double e = view_rms(board, d.corners[c][v], rvecs[v], tvecs[v], K, D);
    (c == 0 ? views[d.used[v]].rms_left : views[d.used[v]].rms_right) = e;
  }
  return rms;
}

}  // namespace

CheckerboardResult calibrate_checkerboard(const std::vector<std::string>& left,
                                          const std::vector<std::string>& right,
                                          const CheckerboardParams& p,
                                          const std::function<void(const std::string&)>& progress) {
  check_inputs(left, right, p);
  const std::vector<cv::Point3f> board = board_points(p);
  CheckerboardResult result;
  const Detections d = find_boards(left, right, p, progress, result.views);
  require_three_views(p, d.corners[0].size());
  const std::vector<std::vector<cv::Point3f>> boards(d.corners[0].size(), board);
  cv::Mat K[2], D[2];
  double rms[2];
  for (int c = 0; c < 2; ++c) rms[c] = calibrate_one(c, board, boards, d, K[c], D[c], result.views);
  cv::Mat R, T, E, F;
  result.rms_stereo = cv::stereoCalibrate(boards, d.corners[0], d.corners[1], K[0], D[0], K[1],
                                          D[1], d.size, R, T, E, F, cv::CALIB_FIX_INTRINSIC);
  StereoCalibration& s = result.calibration;
  s.left = to_camera(K[0], D[0], cv::Mat::eye(3, 3, CV_64F), cv::Mat::zeros(3, 1, CV_64F), d.size);
  s.right = to_camera(K[1], D[1], R, T, d.size);
  s.rms_left = rms[0];
  s.rms_right = rms[1];
  s.source = "sg-calibrate checkerboard (" + std::to_string(d.corners[0].size()) + " stereo views)";
  return result;
}

}  // namespace sg::vision
