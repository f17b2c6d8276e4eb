#include "vision/calibration_file.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

namespace sg::vision {
namespace {

std::string iso_date_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return text;
}

template <class Matrix>
cv::Mat to_mat(const Matrix& m) {
  cv::Mat out;
  cv::eigen2cv(Eigen::MatrixXd(m), out);
  return out;
}

void write_camera(cv::FileStorage& fs, const std::string& name, const CameraModel& cam,
                  double rms) {
  const Distortion& d = cam.distortion();
  fs << name << "{";
  fs << "K" << to_mat(cam.K());
  fs << "distortion" << cv::Mat(cv::Matx<double, 1, 5>(d.k1, d.k2, d.p1, d.p2, d.k3));
  fs << "R" << to_mat(cam.R());
  fs << "t" << to_mat(cam.t());
  fs << "P" << to_mat(cam.P());
  fs << "rms" << rms;
  fs << "}";
}

/// Reads a rows x cols matrix of doubles at `node`, or throws naming `key`.
cv::Mat read_matrix(const cv::FileNode& node, const std::string& path, const std::string& key,
                    int rows, int cols) {
  if (node.empty()) throw CalibrationError(path + ": key '" + key + "' is missing");
  const std::string shape = "must be a " + std::to_string(rows) + "x" + std::to_string(cols) +
                            " matrix";
  // The size it claims first: OpenCV allocates rows x cols before reading the data (a 40-byte
  // claim of 10^5 x 10^5 asked for 48 GB in fuzz/calibration_fuzz).
  if (!node["rows"].isInt() || !node["cols"].isInt() || static_cast<int>(node["rows"]) != rows ||
      static_cast<int>(node["cols"]) != cols) {
    throw CalibrationError(path + ": key '" + key + "' " + shape);
  }
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception&) {
    m.release();
  }
  if (m.empty() || m.rows != rows || m.cols != cols) {
    throw CalibrationError(path + ": key '" + key + "' " + shape);
  }
  m.convertTo(m, CV_64F);
  if (!cv::checkRange(m)) throw CalibrationError(path + ": key '" + key + "' is not finite");
  return m;
}

CameraModel read_camera(const cv::FileNode& node, const std::string& path, const std::string& name,
                        int width, int height, double* rms) {
  if (node.empty()) throw CalibrationError(path + ": key '" + name + "' is missing");
  const cv::Mat K = read_matrix(node["K"], path, name + ".K", 3, 3);
  const cv::Mat D = read_matrix(node["distortion"], path, name + ".distortion", 1, 5);
  const cv::Mat R = read_matrix(node["R"], path, name + ".R", 3, 3);
  const cv::Mat t = read_matrix(node["t"], path, name + ".t", 3, 1);
  Eigen::Matrix3d R_e;
  Eigen::Vector3d t_e;
  cv::cv2eigen(R, R_e);
  cv::cv2eigen(t, t_e);
  if (!(R_e.transpose() * R_e).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
      R_e.determinant() < 0) {
    throw CalibrationError(path + ": key '" + name + ".R' is not a rotation");
  }
  *rms = node["rms"].empty() ? 0.0 : static_cast<double>(node["rms"]);
  const Intrinsics in{K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2),
                      K.at<double>(1, 2), K.at<double>(0, 1)};
  const Distortion dist{D.at<double>(0), D.at<double>(1), D.at<double>(2), D.at<double>(3),
                        D.at<double>(4)};
  try {
    return CameraModel(width, height, in, dist, R_e, t_e);
  } catch (const std::invalid_argument& e) {
    throw CalibrationError(path + ": " + name + ": " + e.what());
  }
}

}  // namespace

void write_calibration(const std::string& path, const StereoCalibration& c) {
  const std::string temporary = path + ".tmp";
  try {
    cv::FileStorage fs(temporary, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) throw CalibrationError(path + ": cannot write calibration file");
    fs << "format_version" << kCalibrationFormatVersion;
    fs << "date" << (c.date.empty() ? iso_date_now() : c.date);
    fs << "source" << c.source;
    fs << "image_width" << c.left.width() << "image_height" << c.left.height();
    write_camera(fs, "camera_left", c.left, c.rms_left);
    write_camera(fs, "camera_right", c.right, c.rms_right);
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();  // left camera pose in the robot frame
    T.topLeftCorner<3, 3>() = c.left.R().transpose();
    T.topRightCorner<3, 1>() = c.left.centre();
    fs << "T_robot_camera_left" << to_mat(T);
    fs.release();
  } catch (const cv::Exception& e) {
    std::remove(temporary.c_str());
    throw CalibrationError(path + ": cannot write calibration file: " + e.err);
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::remove(temporary.c_str());
    throw CalibrationError(path + ": cannot write calibration file: " + error.message());
  }
}

StereoCalibration read_calibration(const std::string& path) {
  // Only YAML as write_calibration writes it reaches FileStorage: OpenCV 4.6's XML parser
  // dereferences NULL on some malformed files (fuzz/calibration_fuzz.cpp found a 43-byte one).
  std::ifstream file(path, std::ios::binary);
  if (!file) throw CalibrationError(path + ": cannot open calibration file");
  std::string head(5, '\0');
  if (!file.read(head.data(), 5) || head != "%YAML") {
    throw CalibrationError(path + ": not a calibration file (it starts with %YAML:1.0)");
  }
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ))
      throw CalibrationError(path + ": cannot open calibration file");
  } catch (const cv::Exception& e) {
    throw CalibrationError(path + ": not a valid calibration file (" + e.err + ")");
  }
  const cv::FileNode version = fs["format_version"];
  if (version.empty() || !version.isInt())
    throw CalibrationError(path + ": key 'format_version' is missing");
  if (static_cast<int>(version) != kCalibrationFormatVersion) {
    throw CalibrationError(path + ": format_version " + std::to_string(static_cast<int>(version)) +
                           " is not supported (expected " +
                           std::to_string(kCalibrationFormatVersion) + ")");
  }
  for (const char* key : {"image_width", "image_height"}) {
    if (fs[key].empty() || !fs[key].isInt() || static_cast<int>(fs[key]) <= 0)
      throw CalibrationError(path + ": key '" + key + "' must be a positive integer");
  }
  const int width = fs["image_width"], height = fs["image_height"];
  StereoCalibration c;
  c.left = read_camera(fs["camera_left"], path, "camera_left", width, height, &c.rms_left);
  c.right = read_camera(fs["camera_right"], path, "camera_right", width, height, &c.rms_right);
  c.source = fs["source"].empty() ? "" : static_cast<std::string>(fs["source"]);
  c.date = fs["date"].empty() ? "" : static_cast<std::string>(fs["date"]);
  return c;
}

}  // namespace sg::vision
