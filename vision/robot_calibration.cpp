#include "vision/robot_calibration.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "vision/sphere_image.hpp"

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

/// Stop k's orientation: `down` tilted by +-tilt about the tool's x axis (even k) or y axis (odd
/// k), the sign alternating every two stops.
Eigen::Vector3d tilted_rpy(const Eigen::Vector3d& down, double tilt, size_t k) {
  if (tilt == 0) return down;
  const double sign = (k / 2) % 2 == 0 ? 1.0 : -1.0;
  const Eigen::Vector3d axis = k % 2 == 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Matrix3d r =
      rotation(down) * Eigen::AngleAxisd(sign * tilt, axis).toRotationMatrix();
  const Eigen::Vector3d ypr = r.eulerAngles(2, 1, 0);
  return {ypr.z(), ypr.y(), ypr.x()};
}

/// One stop as the hand-eye solve sees it.
struct Seen {
  size_t stop;  ///< index in RobotCalibration::stops()
  Eigen::Vector3d tool;
  Eigen::Matrix3d rotation;
  std::array<Eigen::Vector2d, 2> pixel;  ///< the ball's centre as the images show it
  std::array<double, 2> radius;
  const CalibrationStop* measured;  ///< the blobs as seen (pixel is corrected in place)
};

/// The mean over a stop's blobs in one camera of (centre - the centre the tracker's fit finds on
/// the same sectors of the ball's exact image at x); nullopt when the model fails for one.
std::optional<Eigen::Vector2d> mean_fit_error(
    const std::vector<std::pair<Eigen::Vector2d, uint64_t>>& blobs, const CameraModel& camera,
    const Eigen::Vector3d& x, double ball_radius) {
  if (blobs.empty() || !(ball_radius > 0)) return std::nullopt;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  std::optional<Eigen::Vector2d> fitted;
  for (size_t i = 0; i < blobs.size(); ++i) {
    if (i == 0 || blobs[i].second != blobs[i - 1].second)  // the same sectors: the same model
      fitted = sphere_outline_centre(camera, x, ball_radius, blobs[i].second);
    if (!fitted) return std::nullopt;
    sum += blobs[i].first - *fitted;
  }
  return sum / static_cast<double>(blobs.size());
}

/// The pixels of the ball's centre at each stop from what the images show, with the cameras of
/// the last pass and the ball at tool + R d: project(X) + the mean of each blob's centre less the
/// fit the tracker makes on the ball's exact image (sphere_outline_centre), or without a ball
/// radius the ellipse's centre correction from the image's radius (sphere_centre_pixel).
/// Returns the most a pixel moved (px).
double correct_pixels(std::vector<Seen>& seen, const std::array<DltResult, 2>& cams,
                      const Eigen::Vector3d& d, double ball_radius) {
  double moved = 0;
  for (Seen& s : seen) {
    const Eigen::Vector3d x = s.tool + s.rotation * d;
    for (size_t c = 0; c < 2; ++c) {
      const CameraModel& camera = cams[c].camera;
      const auto centre = camera.project(x);
      const auto error = mean_fit_error(s.measured->blobs[c], camera, x, ball_radius);
      const Eigen::Vector2d pixel =
          centre && error ? Eigen::Vector2d(*centre + *error)
                          : sphere_centre_pixel(camera, s.measured->pixel[c], s.radius[c]);
      moved = std::max(moved, (pixel - s.pixel[c]).norm());
      s.pixel[c] = pixel;
    }
  }
  return moved;
}

/// Unit directions of the offset that the stops observe (columns; see solve_hand_eye).
Eigen::MatrixXd observable_directions(const std::vector<Seen>& seen) {
  Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
  for (const Seen& s : seen) mean += s.rotation / static_cast<double>(seen.size());
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const Seen& s : seen) m += (s.rotation - mean).transpose() * (s.rotation - mean);
  m /= static_cast<double>(seen.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  std::vector<int> keep;
  for (int k = 0; k < 3; ++k) {
    if (eig.eigenvalues()(k) >= 0.05 * 0.05) keep.push_back(k);
  }
  Eigen::MatrixXd b(3, static_cast<Eigen::Index>(keep.size()));
  for (size_t k = 0; k < keep.size(); ++k)
    b.col(static_cast<Eigen::Index>(k)) = eig.eigenvectors().col(keep[k]);
  return b;
}

/// Both cameras' DLT with the ball at tool + R d.
std::array<DltResult, 2> cameras_for(const std::vector<Seen>& seen, const Eigen::Vector3d& d,
                                     int width, int height) {
  std::array<std::vector<Correspondence>, 2> points;
  for (const Seen& s : seen) {
    for (size_t c = 0; c < 2; ++c) points[c].push_back({s.tool + s.rotation * d, s.pixel[c]});
  }
  return {calibrate_dlt(points[0], width, height), calibrate_dlt(points[1], width, height)};
}

/// Residuals (4 per stop: both cameras' u, v) and their Jacobian in the joint parameters
/// theta = (P_left row-major, P_right row-major, y), the ball at tool + R (d0 + B y).
void joint_residuals(const std::vector<Seen>& seen, const Eigen::VectorXd& theta,
                     const Eigen::Vector3d& d0, const Eigen::MatrixXd& b, Eigen::VectorXd& r,
                     Eigen::MatrixXd& j) {
  const Eigen::Index k = b.cols();
  r.setZero(static_cast<Eigen::Index>(4 * seen.size()));
  j.setZero(r.size(), 24 + k);
  const Eigen::Vector3d d = d0 + b * theta.tail(k);
  for (size_t i = 0; i < seen.size(); ++i) {
    const Eigen::Vector4d x = (seen[i].tool + seen[i].rotation * d).homogeneous();
    for (Eigen::Index c = 0; c < 2; ++c) {
      const Eigen::Matrix<double, 3, 4> p =
          Eigen::Map<const Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(theta.data() + 12 * c);
      const Eigen::Vector3d h = p * x;
      if (!(std::abs(h.z()) > 1e-12)) continue;
      const auto row = static_cast<Eigen::Index>(4 * i) + 2 * c;
      const Eigen::Vector2d uv = h.head<2>() / h.z();
      r.segment<2>(row) = uv - seen[i].pixel[static_cast<size_t>(c)];
      for (int a = 0; a < 2; ++a) {
        j.block<1, 4>(row + a, 12 * c + 4 * a) = x.transpose() / h.z();
        j.block<1, 4>(row + a, 12 * c + 8) = -uv(a) * x.transpose() / h.z();
        const Eigen::RowVector3d dx = (p.block<1, 3>(a, 0) - uv(a) * p.block<1, 3>(2, 0)) / h.z();
        j.block(row + a, 24, 1, k) = dx * seen[i].rotation * b;
      }
    }
  }
}

/// Levenberg-Marquardt on the joint reprojection error from the cameras `cams`; returns the
/// offset and counts the rounds in `rounds`.
Eigen::Vector3d joint_offset(const std::vector<Seen>& seen, const std::array<DltResult, 2>& cams,
                             const Eigen::Vector3d& d0, const Eigen::MatrixXd& b, int& rounds) {
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(24 + b.cols());
  for (int c = 0; c < 2; ++c) {
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>>(theta.data() + 12 * c) =
        cams[static_cast<size_t>(c)].P;
  }
  Eigen::VectorXd r, r_try;
  Eigen::MatrixXd j, j_try;
  joint_residuals(seen, theta, d0, b, r, j);
  double lambda = 1e-3;
  for (rounds = 0; rounds < 100 && lambda < 1e12; ++rounds) {
    Eigen::MatrixXd a = j.transpose() * j;
    a.diagonal() += lambda * a.diagonal().cwiseMax(1e-12);
    const Eigen::VectorXd step = a.ldlt().solve(-j.transpose() * r);
    if (!step.allFinite()) break;
    const Eigen::VectorXd next = theta + step;
    joint_residuals(seen, next, d0, b, r_try, j_try);
    if (r_try.squaredNorm() < r.squaredNorm()) {
      const bool settled = (b * step.tail(b.cols())).norm() < 1e-7;
      theta = next, r = r_try, j = j_try, lambda = std::max(lambda / 10, 1e-12);
      if (settled) break;
    } else {
      lambda *= 10;
    }
  }
  return d0 + b * theta.tail(b.cols());
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
  c.numbers("tool_rpy", rpy.data(), 3, Range::closed(-7, 7),
            "tool roll pitch yaw at every stop (rad)");
  if (rpy_given) p.tool_rpy = rpy;
  c.numbers("ball_offset", p.ball_offset.data(), 3, Range::closed(-1, 1),
            "the ball's centre from the tool centre point, tool frame (m): the first guess");
  c.flag("estimate_ball_offset", p.estimate_ball_offset,
         "estimate the ball's offset on the tool with the cameras (hand-eye)");
  c.number("offset_gain", p.offset_gain, Range::closed(0, 1),
           "the estimated offset is kept when it brings the RMS reprojection error to this "
           "fraction of the configured offset's or below");
  c.number("tilt", p.tilt, Range::closed(0, 0.8),
           "rad of tool tilt, alternating at the stops (0: all tool-down)");
  c.number("min_fit_support", p.min_fit_support, Range::closed(0, 1),
           "least share of the ball's outline a blob must show to be averaged");
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
        stop.rpy =
            tilted_rpy(p.tool_rpy ? *p.tool_rpy : tool_down_rpy(stop.tool), p.tilt, stops_.size());
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

void RobotCalibration::on_blob(int camera, int64_t utime, bool found, const Eigen::Vector2d& centre,
                               double fit_support, double radius, uint64_t arc) {
  if (done() || phase_ != Phase::kSettling || camera < 0 || camera > 1) return;
  if (utime < arrived_utime_ + static_cast<int64_t>(params_.settle * 1e6)) return;
  CalibrationStop& stop = stops_[current_];
  const auto c = static_cast<size_t>(camera);
  const bool hidden = found && fit_support < params_.min_fit_support;  // false for NaN
  // Any host can send BLOB_*: a centre off the image is no camera's and is refused.
  const bool refused = found && !(centre.x() >= -0.5 && centre.x() <= params_.image_width - 0.5 &&
                                  centre.y() >= -0.5 && centre.y() <= params_.image_height - 0.5);
  if (!found || refused || hidden) {
    stop.hidden += hidden ? 1 : 0;
    stop.refused += refused ? 1 : 0;
    if (++stop.misses >= params_.max_misses_per_stop) {
      stop.skipped = true;
      finish_stop();
    }
    return;
  }
  if (stop.frames[c] >= params_.frames_per_stop) return;
  sums_[c] += centre;
  const bool sized = std::isfinite(radius) && radius > 0 && radius < params_.image_width;
  radius_sums_[c] += sized ? radius : 0;
  stop.blobs[c].emplace_back(centre, arc);
  ++stop.frames[c];
  if (stop.frames[0] >= params_.frames_per_stop && stop.frames[1] >= params_.frames_per_stop)
    finish_stop();
}

void RobotCalibration::finish_stop() {
  CalibrationStop& stop = stops_[current_];
  for (size_t c = 0; c < 2; ++c) {
    if (stop.frames[c] > 0) stop.pixel[c] = sums_[c] / stop.frames[c];
    if (stop.frames[c] > 0) stop.radius[c] = radius_sums_[c] / stop.frames[c];
  }
  sums_ = {Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  radius_sums_ = {0, 0};
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

HandEyeSolution RobotCalibration::solve_hand_eye() const {
  std::vector<Seen> seen;
  for (size_t i = 0; i < stops_.size(); ++i) {
    const CalibrationStop& s = stops_[i];
    if (s.skipped || s.frames[0] == 0 || s.frames[1] == 0) continue;
    seen.push_back({i, s.tool, rotation(s.rpy), s.pixel, s.radius, &s});
  }
  if (seen.size() < 6) {
    throw CalibrationInputError("the ball was seen by both cameras at only " +
                                std::to_string(seen.size()) + " stops; the DLT needs 6");
  }
  const int w = params_.image_width, h = params_.image_height;
  HandEyeSolution out;
  out.ball_offset = params_.ball_offset;
  const Eigen::MatrixXd b =
      params_.estimate_ball_offset ? observable_directions(seen) : Eigen::MatrixXd(3, 0);
  out.offset_dims = static_cast<int>(b.cols());
  std::array<DltResult, 2> cams;
  for (double moved = INFINITY; out.passes < kMaxPasses && moved > kPixelsSettled; ++out.passes) {
    // The pixels of the ball's centre, with the last pass's cameras.
    if (out.passes > 0) moved = correct_pixels(seen, cams, out.ball_offset, params_.ball_radius);
    out.ball_offset = params_.ball_offset;
    cams = cameras_for(seen, out.ball_offset, w, h);
    out.rms_configured = std::hypot(cams[0].rms, cams[1].rms) / std::sqrt(2.0);
    out.rms_estimated = out.rms_configured;
    if (out.offset_dims == 0) continue;
    const Eigen::Vector3d d = joint_offset(seen, cams, out.ball_offset, b, out.iterations);
    const std::array<DltResult, 2> with_d = cameras_for(seen, d, w, h);
    out.rms_estimated = std::hypot(with_d[0].rms, with_d[1].rms) / std::sqrt(2.0);
    out.offset_accepted = out.rms_estimated <= params_.offset_gain * out.rms_configured;
    if (out.offset_accepted) out.ball_offset = d, cams = with_d;
  }
  out.cameras.left = cams[0].camera;
  out.cameras.right = cams[1].camera;
  out.cameras.rms_left = cams[0].rms;
  out.cameras.rms_right = cams[1].rms;
  out.cameras.source = "sg-calibrate robot (" + std::to_string(seen.size()) + " stops)";
  out.residual.assign(stops_.size(), {NAN, NAN});
  for (const Seen& s : seen) {
    const Eigen::Vector3d x = s.tool + s.rotation * out.ball_offset;
    for (size_t c = 0; c < 2; ++c) {
      const auto px = cams[c].camera.project(x);
      out.residual[s.stop][c] = px ? (*px - s.pixel[c]).norm() : NAN;
    }
  }
  return out;
}

}  // namespace sg::vision
