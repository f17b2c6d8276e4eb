#include "vision/calibration_file.hpp"

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>
#include <utility>

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

/// Whether a key is there with a value (a missing key's node is not defined, and asking it for
/// its type throws).
bool present(const YAML::Node& node) { return node.IsDefined() && !node.IsNull(); }

/// Whether `text` is one line of printable text no longer than kCalibrationTextMax: what
/// FileStorage writes back as it was read (it stops at a NUL byte, and refuses strings over
/// 4096 bytes; fuzz/calibration_fuzz found a date holding NULs that came back shorter).
bool is_one_line_of_text(const std::string& text) {
  if (text.size() > kCalibrationTextMax) return false;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) return false;
  }
  return true;
}

/// "FILE:LINE: key 'KEY' ": where an error is (the line of the node when it has one).
std::string where(const std::string& path, const YAML::Node& node, const std::string& key) {
  const YAML::Mark mark = node.IsDefined() ? node.Mark() : YAML::Mark::null_mark();
  std::string out = path;  // appended piecewise: GCC 12's -Wrestrict misfires on a + chain here
  if (!mark.is_null()) out.append(":").append(std::to_string(mark.line + 1));
  return out.append(": key '").append(key).append("' ");
}

/// The scalar at `node` as T, or throws naming `key` and `what` it must be.
template <class T>
T scalar(const YAML::Node& node, const std::string& path, const std::string& key,
         const std::string& what) {
  if (!present(node)) throw CalibrationError(where(path, node, key) + "is missing");
  T value{};
  if (!node.IsScalar() || !YAML::convert<T>::decode(node, value))
    throw CalibrationError(where(path, node, key) + "must be " + what);
  return value;
}

/// Reads the rows x cols matrix of doubles at `node`, as FileStorage writes one
/// (`!!opencv-matrix` {rows, cols, dt, data: [row-major values]}), or throws naming `key`.
/// The size it claims is checked before anything else is read.
Eigen::MatrixXd read_matrix(const YAML::Node& node, const std::string& path, const std::string& key,
                            int rows, int cols) {
  if (!present(node)) throw CalibrationError(where(path, node, key) + "is missing");
  const std::string shape =
      "must be a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix";
  if (!node.IsMap()) throw CalibrationError(where(path, node, key) + shape);
  const auto is = [&](const char* k, int expected) {
    const YAML::Node n = node[k];
    int value = 0;
    return n.IsDefined() && n.IsScalar() && YAML::convert<int>::decode(n, value) &&
           value == expected;
  };
  const YAML::Node data = node["data"];
  if (!is("rows", rows) || !is("cols", cols) || !data.IsDefined() || !data.IsSequence() ||
      data.size() != static_cast<std::size_t>(rows * cols)) {
    throw CalibrationError(where(path, node, key) + shape);
  }
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows * cols; ++i) {
    double v = 0;
    if (!data[i].IsScalar() || !YAML::convert<double>::decode(data[i], v))
      throw CalibrationError(where(path, node, key) + shape + " of numbers");
    if (!std::isfinite(v)) throw CalibrationError(where(path, node, key) + "is not finite");
    m(i / cols, i % cols) = v;
  }
  return m;
}

CameraModel read_camera(const YAML::Node& node, const std::string& path, const std::string& name,
                        int width, int height, double* rms) {
  if (!present(node)) throw CalibrationError(where(path, node, name) + "is missing");
  if (!node.IsMap()) throw CalibrationError(where(path, node, name) + "must be a map");
  const Eigen::Matrix3d K = read_matrix(node["K"], path, name + ".K", 3, 3);
  const Eigen::MatrixXd D = read_matrix(node["distortion"], path, name + ".distortion", 1, 5);
  const Eigen::Matrix3d R = read_matrix(node["R"], path, name + ".R", 3, 3);
  const Eigen::Vector3d t = read_matrix(node["t"], path, name + ".t", 3, 1);
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0)
    throw CalibrationError(where(path, node["R"], name + ".R") + "is not a rotation");
  *rms = present(node["rms"]) ? scalar<double>(node["rms"], path, name + ".rms", "a number") : 0.0;
  if (!std::isfinite(*rms))
    throw CalibrationError(where(path, node["rms"], name + ".rms") + "is not finite");
  const Intrinsics in{K(0, 0), K(1, 1), K(0, 2), K(1, 2), K(0, 1)};
  const Distortion dist{D(0), D(1), D(2), D(3), D(4)};
  try {
    return CameraModel(width, height, in, dist, R, t);
  } catch (const std::invalid_argument& e) {
    throw CalibrationError(path + ": " + name + ": " + e.what());
  }
}

/// The file as yaml-cpp reads it: write_calibration's first line, OpenCV's "%YAML:1.0" (not
/// a YAML 1.x directive), becomes an empty line so the line numbers stay the file's.
YAML::Node parse_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw CalibrationError(path + ": cannot open calibration file");
  std::stringstream text;
  text << file.rdbuf();
  std::string yaml = text.str();
  if (!yaml.starts_with("%YAML:1.0\n"))
    throw CalibrationError(path + ": not a calibration file (it starts with %YAML:1.0)");
  yaml.erase(0, yaml.find('\n'));
  try {
    return YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw CalibrationError(path + ":" + std::to_string(e.mark.line + 1) +
                           ": not a valid calibration file (" + e.msg + ")");
  }
}

}  // namespace

void write_calibration(const std::string& path, const StereoCalibration& c) {
  for (const auto& [key, text] : {std::pair{"source", &c.source}, {"date", &c.date}}) {
    if (!is_one_line_of_text(*text))
      throw CalibrationError(path + ": " + key + " " + kCalibrationTextRule);
  }
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
  // Read with yaml-cpp, not FileStorage: OpenCV 4.6's parsers dereference NULL on some
  // malformed XML and loop for ever on some truncated YAML (fuzz/calibration_fuzz found both).
  const YAML::Node root = parse_file(path);
  if (!root.IsMap()) throw CalibrationError(path + ": not a calibration file (not a map)");
  try {
    const int version = scalar<int>(root["format_version"], path, "format_version", "an integer");
    if (version != kCalibrationFormatVersion) {
      throw CalibrationError(path + ": format_version " + std::to_string(version) +
                             " is not supported (expected " +
                             std::to_string(kCalibrationFormatVersion) + ")");
    }
    const int width = scalar<int>(root["image_width"], path, "image_width", "a positive integer");
    const int height =
        scalar<int>(root["image_height"], path, "image_height", "a positive integer");
    if (width <= 0 || height <= 0) {
      throw CalibrationError(path + ": key '" + (width <= 0 ? "image_width" : "image_height") +
                             "' must be a positive integer");
    }
    StereoCalibration c;
    c.left = read_camera(root["camera_left"], path, "camera_left", width, height, &c.rms_left);
    c.right = read_camera(root["camera_right"], path, "camera_right", width, height, &c.rms_right);
    for (auto [key, out] : {std::pair{"source", &c.source}, {"date", &c.date}}) {
      if (!present(root[key])) continue;
      *out = scalar<std::string>(root[key], path, key, "a string");
      if (!is_one_line_of_text(*out))
        throw CalibrationError(where(path, root[key], key) + kCalibrationTextRule);
    }
    return c;
  } catch (const YAML::Exception& e) {  // e.g. a node used as a map that is not one
    throw CalibrationError(path + ":" + std::to_string(e.mark.line + 1) +
                           ": not a valid calibration file (" + e.msg + ")");
  }
}

}  // namespace sg::vision
