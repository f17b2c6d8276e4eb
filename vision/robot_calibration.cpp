#include "vision/robot_calibration.hpp"

#include <Eigen/Geometry>

namespace sg::vision {
namespace {

Eigen::Matrix3d rotation(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

double lerp(double a, double b, int i, int n) {
  return n == 1 ? (a + b) / 2 : a + (b - a) * i / (n - 1);
}

}  // namespace

RobotCalibration::RobotCalibration(const RobotCalibrationParams& p, int64_t first_sequence)
    : params_(p), sequence_(first_sequence - 1) {
  if (p.nx < 1 || p.ny < 1 || p.nz < 1 || p.nx * p.ny * p.nz < 12)
    throw CalibrationInputError("the robot calibration grid needs at least 12 positions");
  if (p.nz < 2)
    throw CalibrationInputError(
        "the grid needs at least 2 heights: the DLT needs points off a plane");
  const Eigen::Vector3d offset = rotation(p.tool_rpy) * p.ball_offset;
  for (int k = 0; k < p.nz; ++k) {
    for (int j = 0; j < p.ny; ++j) {
      for (int i = 0; i < p.nx; ++i) {
        // A serpentine order keeps the moves short.
        const int ii = (j % 2 == 0) ? i : p.nx - 1 - i;
        CalibrationStop stop;
        stop.tool = {lerp(p.box_min.x(), p.box_max.x(), ii, p.nx),
                     lerp(p.box_min.y(), p.box_max.y(), j, p.ny),
                     lerp(p.box_min.z(), p.box_max.z(), k, p.nz)};
        stop.ball = stop.tool + offset;
        stops_.push_back(stop);
      }
    }
  }
  sums_ = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
}

std::optional<ArmTarget> RobotCalibration::next_target() {
  if (done() || phase_ != Phase::kSend) return std::nullopt;
  phase_ = Phase::kMoving;
  return ArmTarget{++sequence_, stops_[current_].tool, params_.tool_rpy, params_.speed};
}

void RobotCalibration::on_arm_status(int64_t utime, int64_t last_executed, bool idle) {
  if (phase_ == Phase::kMoving && idle && last_executed >= sequence_) {
    phase_ = Phase::kSettling;
    arrived_utime_ = utime;
  }
}

void RobotCalibration::on_blob(int camera, int64_t utime, bool found,
                               const Eigen::Vector2d& centroid) {
  if (done() || phase_ != Phase::kSettling || camera < 0 || camera > 1) return;
  if (utime < arrived_utime_ + static_cast<int64_t>(params_.settle * 1e6)) return;
  CalibrationStop& stop = stops_[current_];
  const auto c = static_cast<size_t>(camera);
  if (!found || !centroid.allFinite()) {
    if (++stop.misses >= params_.max_misses_per_stop) {
      stop.skipped = true;
      finish_stop();
    }
    return;
  }
  if (stop.frames[c] >= params_.frames_per_stop) return;
  sums_[c] += centroid;
  ++stop.frames[c];
  if (stop.frames[0] >= params_.frames_per_stop && stop.frames[1] >= params_.frames_per_stop)
    finish_stop();
}

void RobotCalibration::finish_stop() {
  CalibrationStop& stop = stops_[current_];
  for (size_t c = 0; c < 2; ++c) {
    if (stop.frames[c] > 0) stop.pixel[c] = sums_[c] / stop.frames[c];
  }
  sums_ = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  ++current_;
  phase_ = Phase::kSend;
}

std::string RobotCalibration::progress() const {
  if (done()) return "all " + std::to_string(stops_.size()) + " stops visited";
  const CalibrationStop& s = stops_[current_];
  std::string text =
      "stop " + std::to_string(current_ + 1) + " of " + std::to_string(stops_.size()) + ": ";
  if (phase_ == Phase::kMoving) return text + "moving";
  if (phase_ == Phase::kSend) return text + "next";
  return text + "collecting (left " + std::to_string(s.frames[0]) + "/" +
         std::to_string(params_.frames_per_stop) + ", right " + std::to_string(s.frames[1]) + "/" +
         std::to_string(params_.frames_per_stop) + ")";
}

StereoCalibration RobotCalibration::solve() const {
  std::array<std::vector<Correspondence>, 2> points;
  for (const CalibrationStop& s : stops_) {
    if (s.skipped || s.frames[0] == 0 || s.frames[1] == 0) continue;
    for (size_t c = 0; c < 2; ++c) points[c].push_back({s.ball, s.pixel[c]});
  }
  if (points[0].size() < 6) {
    throw CalibrationInputError("the ball was seen by both cameras at only " +
                                std::to_string(points[0].size()) + " stops; the DLT needs 6");
  }
  StereoCalibration out;
  const DltResult left = calibrate_dlt(points[0], params_.image_width, params_.image_height);
  const DltResult right = calibrate_dlt(points[1], params_.image_width, params_.image_height);
  out.left = left.camera;
  out.right = right.camera;
  out.rms_left = left.rms;
  out.rms_right = right.rms;
  out.source = "sg-calibrate robot (" + std::to_string(points[0].size()) + " stops)";
  return out;
}

}  // namespace sg::vision
