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

}  // namespace

CheckerboardResult calibrate_checkerboard(const std::vector<std::string>& left,
                                          const std::vector<std::string>& right,
                                          const CheckerboardParams& p,
                                          const std::function<void(const std::string&)>& progress) {
  if (left.size() != right.size()) {
    throw CalibrationInputError(std::to_string(left.size()) + " left images but " +
                                std::to_string(right.size()) + " right images");
  }
  if (p.pattern.width < 2 || p.pattern.height < 2 || !(p.square > 0))
    throw CalibrationInputError(
        "the pattern needs at least 2x2 inner corners and a positive square");
  std::vector<cv::Point3f> board;
  for (int y = 0; y < p.pattern.height; ++y) {
    for (int x = 0; x < p.pattern.width; ++x) {
      board.emplace_back(static_cast<float>(x * p.square), static_cast<float>(y * p.square), 0.0f);
    }
  }
  CheckerboardResult result;
  cv::Size size;
  std::vector<std::vector<cv::Point2f>> corners[2];
  std::vector<size_t> used;
  for (size_t i = 0; i < left.size(); ++i) {
    ViewReport view;
    view.left = left[i];
    view.right = right[i];
    std::vector<cv::Point2f> l, r;
    if (progress) progress(left[i]);
    const bool found_left = find_corners(left[i], p, size, l);
    if (progress) progress(right[i]);
    const bool found_right = find_corners(right[i], p, size, r);
    if (found_left && found_right) {
      view.used = true;
      corners[0].push_back(l);
      corners[1].push_back(r);
      used.push_back(result.views.size());
    } else {
      view.dropped_because = std::string("board not found in the ") +
                             (!found_left && !found_right ? "left and right images"
                              : !found_left               ? "left image"
                                                          : "right image");
    }
    result.views.push_back(view);
  }
  if (corners[0].size() < 3) {
    throw CalibrationInputError("the " + std::to_string(p.pattern.width) + "x" +
                                std::to_string(p.pattern.height) + " board was found in " +
                                std::to_string(corners[0].size()) +
                                " stereo pairs; at least 3 are needed (wrong --pattern?)");
  }
  const std::vector<std::vector<cv::Point3f>> boards(corners[0].size(), board);
  cv::Mat K[2], D[2];
  double rms[2];
  for (int c = 0; c < 2; ++c) {
    std::vector<cv::Mat> rvecs, tvecs;
    rms[c] =
        cv::calibrateCamera(boards, corners[c], size, K[c], D[c], rvecs, tvecs, cv::CALIB_FIX_K3);
    for (size_t v = 0; v < used.size(); ++v) {
      const double e = view_rms(board, corners[c][v], rvecs[v], tvecs[v], K[c], D[c]);
      (c == 0 ? result.views[used[v]].rms_left : result.views[used[v]].rms_right) = e;
    }
  }
  cv::Mat R, T, E, F;
  result.rms_stereo = cv::stereoCalibrate(boards, corners[0], corners[1], K[0], D[0], K[1], D[1],
                                          size, R, T, E, F, cv::CALIB_FIX_INTRINSIC);
  StereoCalibration& s = result.calibration;
  s.left = to_camera(K[0], D[0], cv::Mat::eye(3, 3, CV_64F), cv::Mat::zeros(3, 1, CV_64F), size);
  s.right = to_camera(K[1], D[1], R, T, size);
  s.rms_left = rms[0];
  s.rms_right = rms[1];
  s.source = "sg-calibrate checkerboard (" + std::to_string(corners[0].size()) + " stereo views)";
  return result;
}

}  // namespace sg::vision
