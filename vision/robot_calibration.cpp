#include "vision/robot_calibration.hpp"

#include <Eigen/Geometry>
#include <cmath>

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

Eigen::Vector3d tool_down_rpy(const Eigen::Vector3d& position) {
  return {M_PI, 0.0, std::remainder(std::atan2(position.y(), position.x()) + M_PI, 2 * M_PI)};
}

RobotCalibrationParams load_robot_calibration_params(const Config& config) {
  RobotCalibrationParams p;
  Section c(config, "calibrate_robot");
  c.numbers("box_min", p.box_min.data(), 3, Range::closed(-10, 10),
            "a corner of the grid of the tool centre point, robot frame (m)");
  c.numbers("box_max", p.box_max.data(), 3, Range::closed(-10, 10), "the opposite corner (m)");
  if (!(p.box_min.array() <= p.box_max.array()).all())
    throw c.error("box_max", "must be at least box_min on every axis");
  std::vector<int> g = {p.nx, p.ny, p.nz};
  const std::string grid_default = show({1.0 * p.nx, 1.0 * p.ny, 1.0 * p.nz});
  if (c.read("grid", g, grid_default, "points per axis nx ny nz (nz >= 2, 12 in all)", 3)) {
    if (g.size() != 3 || g[0] < 1 || g[1] < 1 || g[2] < 2 || g[0] > 100 || g[1] > 100 ||
        g[2] > 100 || g[0] * g[1] * g[2] < 12)
      throw c.error("grid", "must be [nx, ny, nz], each at most 100, nz >= 2, at least 12 points");
    p.nx = g[0], p.ny = g[1], p.nz = g[2];
  }
  Eigen::Vector3d rpy(M_PI, 0, 0);
  const bool rpy_given =
      c.known("tool_rpy", "pi 0 atan2(y,x)+pi", "tool roll pitch yaw at every stop (rad)", 3);
  c.numbers("tool_rpy", rpy.data(), 3, Range::closed(-7, 7), "tool roll pitch yaw at every stop (rad)");
  if (rpy_given) p.tool_rpy = rpy;
  c.numbers("ball_offset", p.ball_offset.data(), 3, Range::closed(-1, 1),
            "the ball's centre from the tool centre point, tool frame (m)");
  c.number("speed", p.speed, Range::above_to(0, 1), "arm speed, fraction of the joint limits");
  c.number("frames_per_stop", p.frames_per_stop, Range::closed(1, 10000),
           "blobs averaged per camera at each stop");
  c.number("settle", p.settle, Range::closed(0, 600), "s after arrival before blobs count");
  c.number("max_misses_per_stop", p.max_misses_per_stop, Range::closed(1, 1e6),
           "frames without the ball before a stop is skipped");
  c.number("timeout", p.timeout, Range::above_to(0, 86400), "s without progress before giving up");
  c.done();
  return p;
}

RobotCalibration::RobotCalibration(const RobotCalibrationParams& p, int64_t first_sequence)
    : params_(p), sequence_(first_sequence - 1) {
  if (p.nx < 1 || p.ny < 1 || p.nz < 1 || p.nx * p.ny * p.nz < 12)
    throw CalibrationInputError("the robot calibration grid needs at least 12 positions");
  if (p.nz < 2)
    throw CalibrationInputError(
        "the grid needs at least 2 heights: the DLT needs points off a plane");
  for (int k = 0; k < p.nz; ++k) {
    for (int j = 0; j < p.ny; ++j) {
      for (int i = 0; i < p.nx; ++i) {
        // A serpentine order keeps the moves short.
        const int ii = (j % 2 == 0) ? i : p.nx - 1 - i;
        CalibrationStop stop;
        stop.tool = {lerp(p.box_min.x(), p.box_max.x(), ii, p.nx),
                     lerp(p.box_min.y(), p.box_max.y(), j, p.ny),
                     lerp(p.box_min.z(), p.box_max.z(), k, p.nz)};
        stop.rpy = p.tool_rpy ? *p.tool_rpy : tool_down_rpy(stop.tool);
        stop.ball = stop.tool + rotation(stop.rpy) * p.ball_offset;
        stops_.push_back(stop);
      }
    }
  }
  sums_ = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
}

std::optional<ArmTarget> RobotCalibration::next_target() {
  if (done() || phase_ != Phase::kSend) return std::nullopt;
  phase_ = Phase::kMoving;
  return ArmTarget{++sequence_, stops_[current_].tool, stops_[current_].rpy, params_.speed};
}

void RobotCalibration::on_arm_status(int64_t utime, int64_t last_executed, bool idle) {
  if (phase_ == Phase::kMoving && idle && last_executed >= sequence_) {
    phase_ = Phase::kSettling;
    arrived_utime_ = utime;
  }
}

void RobotCalibration::on_arm_rejected(int64_t sequence, const std::string& reason) {
  if (done() || phase_ != Phase::kMoving || sequence != sequence_) return;
  stops_[current_].rejected = reason.empty() ? "rejected" : reason;
  stops_[current_].skipped = true;
  finish_stop();
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
