#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "vision/calibration_file.hpp"

namespace sg::vision {

/// The printed board: inner corners per row and column, and the side of a square (m).
struct CheckerboardParams {
  cv::Size pattern{9, 6};
  double square = 0.025;
};

/// What happened to one stereo view.
struct ViewReport {
  std::string left, right;  ///< file names
  bool used = false;
  std::string dropped_because;         ///< when not used: which image the board was not found in
  double rms_left = 0, rms_right = 0;  ///< this view's reprojection RMS per camera, px
};

/// A stereo calibration from images of a checkerboard.
struct CheckerboardResult {
  StereoCalibration calibration;  ///< in the left camera's frame (robot frame after registration)
  std::vector<ViewReport> views;
  double rms_stereo = 0;  ///< stereoCalibrate's RMS over both cameras, px
};

/// Intrinsics and distortion per camera (OpenCV's chessboard detection, sub-pixel corners,
/// calibrateCamera), then the pair's extrinsics (stereoCalibrate with those intrinsics fixed).
/// Left and right images are paired in the order given; a pair whose board is not found in both
/// is dropped and reported. Throws CalibrationInputError for unreadable images, mismatched counts,
/// images of different sizes or fewer than 3 usable pairs. `progress` is told each image.
CheckerboardResult calibrate_checkerboard(
    const std::vector<std::string>& left_images, const std::vector<std::string>& right_images,
    const CheckerboardParams& params,
    const std::function<void(const std::string&)>& progress = nullptr);

}  // namespace sg::vision
