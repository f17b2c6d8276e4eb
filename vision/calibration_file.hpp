#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "vision/camera_model.hpp"

namespace sg::vision {

/// A calibration file that cannot be read or written; the message names the file and the key.
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What a stereo calibration file holds: both cameras in the robot base frame and how well they
/// were estimated. Written by sg-calibrate, and by sg-camera-sim as the simulator's true
/// calibration, so the two can be compared.
struct StereoCalibration {
  CameraModel left;
  CameraModel right;
  double rms_left = 0.0;   ///< RMS reprojection error of the left camera, pixels
  double rms_right = 0.0;  ///< RMS reprojection error of the right camera, pixels
  std::string source;      ///< what produced it (e.g. "sg-camera-sim true calibration")
  std::string date;        ///< when, ISO 8601 (filled by write_calibration when empty)
};

/// The file format's version; read_calibration refuses other versions.
inline constexpr int kCalibrationFormatVersion = 1;

/// The longest `source` or `date` a calibration file holds, in bytes.
inline constexpr std::size_t kCalibrationTextMax = 1024;
/// What `source` and `date` must be; read_calibration and write_calibration refuse other text.
inline constexpr const char* kCalibrationTextRule =
    "must be one line of text (no control characters, at most 1024 bytes)";

/// Writes YAML that OpenCV's FileStorage reads: format_version, date, source, image size and,
/// per camera (`camera_left`, `camera_right`), K, distortion (k1 k2 p1 p2 k3), R and t (robot base
/// frame to camera frame), P = K [R|t], rms; and `T_robot_camera_left`, the left camera's pose in
/// the robot frame (4x4). Written to a temporary file and renamed, so a failure never leaves a
/// partial file over a good one. Throws CalibrationError when `source` or `date` is not
/// kCalibrationTextRule's text, or the file cannot be written.
void write_calibration(const std::string& path, const StereoCalibration& calibration);

/// Reads a file written by write_calibration (with yaml-cpp: OpenCV's FileStorage parser crashes
/// or hangs on some malformed files); throws CalibrationError naming a missing or malformed key
/// and its line.
StereoCalibration read_calibration(const std::string& path);

}  // namespace sg::vision
