#include "grasp/interception.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>
#include <utility>

namespace sg::grasp {

using arm::IkResult;
using arm::motion_time;
using arm::pose_from_xyz_rpy;
using arm::rpy_from_rotation;
using arm::solve_nearest;
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kOnAxis = 1e-12;  // m: a target this close to the base axis has no azimuth

/// Microseconds in `seconds`, rounded to the nearest.
int64_t to_us(double seconds) { return std::llround(seconds * 1e6); }

/// The wrist centre in the tool frame: the flange frame's (0, 0, -d6) seen from the TCP.
Eigen::Vector3d wrist_in_tool(const ArmGeometry& arm) {
  return arm.tool.inverse() * Eigen::Vector3d(0, 0, -arm.links[5].d);
}

/// The tilt with |tilt| smallest among the solutions of |w(tilt) - s| = distance, where
/// |w - s|^2 = k - 2 L R sin(tilt - phi) (see approach_pose()). When no tilt reaches
/// `distance`, the tilt that comes closest (sin(tilt - phi) = +-1).
double tilt_for_distance(double k, double L, double R, double phi, double distance) {
  const double c = std::clamp((k - distance * distance) / (2 * L * R), -1.0, 1.0);
  const double s = std::asin(c);
  const double t1 = std::remainder(phi + s, 2 * kPi);  // in [-pi, pi]
  const double t2 = std::remainder(phi + kPi - s, 2 * kPi);
  return std::abs(t1) <= std::abs(t2) ? t1 : t2;
}

Interception fail(Interception out, std::string error) {
  out.ok = false;
  out.error = std::move(error);
  return out;
}

}  // namespace

PredictedPath PredictedPath::hold(const Eigen::Vector3d& position, int64_t utime, int64_t period_us,
                                  int count) {
  PredictedPath path;
  path.utime = utime;
  path.start_utime = utime + period_us;
  path.period_us = period_us;
  path.points.assign(static_cast<std::size_t>(std::max(count, 0)), position);
  return path;
}

int64_t PredictedPath::end_utime() const {
  if (points.empty()) return start_utime;
  return start_utime + static_cast<int64_t>(points.size() - 1) * period_us;
}

namespace {

/// values[] (one per point of `path`) at `t`, linearly interpolated; before start_utime the first
/// segment extended back when `extend_back`, else values[0].
std::optional<Eigen::Vector3d> interpolate(const PredictedPath& path,
                                           const std::vector<Eigen::Vector3d>& values, int64_t t,
                                           bool extend_back) {
  if (path.lost || values.empty() || values.size() != path.points.size() || t < path.utime ||
      t > path.end_utime()) {
    return std::nullopt;
  }
  if (values.size() == 1) return values[0];
  if (path.period_us <= 0) return std::nullopt;  // malformed: the points have no times
  const int64_t since = t - path.start_utime;
  if (since < 0) {  // back-extension along the first segment (a negative fraction)
    if (!extend_back) return values[0];
    const double f = static_cast<double>(since) / static_cast<double>(path.period_us);
    return Eigen::Vector3d(values[0] + f * (values[1] - values[0]));
  }
  const auto i = static_cast<std::size_t>(since / path.period_us);
  const int64_t rest = since % path.period_us;
  if (rest == 0) return values[i];  // exactly at a point (includes the last one)
  const double f = static_cast<double>(rest) / static_cast<double>(path.period_us);
  return Eigen::Vector3d(values[i] + f * (values[i + 1] - values[i]));
}

}  // namespace

std::optional<Eigen::Vector3d> PredictedPath::at(int64_t t) const {
  return interpolate(*this, points, t, /*extend_back=*/true);
}

std::optional<Eigen::Vector3d> PredictedPath::sigma_at(int64_t t) const {
  return interpolate(*this, sigmas, t, /*extend_back=*/false);
}

// The lean. Let e_r = (cos az, sin az, 0) be the horizontal unit vector from the base axis
// toward the target (az its azimuth) and e_z = (0, 0, 1). The tool axis u (unit, from the wrist
// toward the TCP) leaned by `tilt` in the vertical plane through e_r and e_z is
//
//   u(tilt) = sin(tilt) e_r - cos(tilt) e_z       (tilt = 0: straight down; tilt > 0: the tool
//                                                  points outward, away from the base)
//
// and its rotation is R = Rz(az) Ry(pi - tilt): Ry(pi - tilt) e_z = (sin(tilt), 0, -cos(tilt)),
// and at tilt = 0, Rz(az) Ry(pi) = Rz(az + pi) Rx(pi), i.e. rpy (pi, 0, az + pi). The rotation
// about the tangential axis only (no roll about u) keeps joints 4 and 6 near zero.
//
// The wrist centre is w = tcp - L u (L = d6 + the tool offset along the tool axis), so with
// the shoulder s = (0, 0, d1), a = |tcp_xy| and b = tcp.z - d1, in the (e_r, e_z) plane
//
//   w - s = (a - L sin(tilt), b + L cos(tilt))
//   |w - s|^2 = a^2 - 2 a L sin(tilt) + L^2 sin^2 + b^2 + 2 b L cos(tilt) + L^2 cos^2
//             = a^2 + b^2 + L^2 - 2 L (a sin(tilt) - b cos(tilt))
//             = k - 2 L R sin(tilt - phi),   k = a^2 + b^2 + L^2, R = hypot(a, b),
//                                            phi = atan2(b, a)
//
// since a sin(t) - b cos(t) = R (cos(phi) sin(t) - sin(phi) cos(t)) = R sin(t - phi). For a
// required distance D: sin(tilt - phi) = (k - D^2) / (2 L R), two solutions per period. The set of
// tilts that keep the wrist within [wrist_min, wrist_max] is an arc; when tilt = 0 is outside it,
// the nearest point of the arc is a solution for D = wrist_min (wrist too close) or D = wrist_max
// (too far), the one with the smallest |tilt|. Finally |tilt| <= max_tilt.
ApproachPose approach_pose(const ArmGeometry& arm, const Eigen::Vector3d& tcp,
                           const InterceptionSettings& settings) {
  ApproachPose pose;
  pose.position = tcp;
  const double a = std::hypot(tcp.x(), tcp.y());
  const double azimuth = a < kOnAxis ? 0.0 : std::atan2(tcp.y(), tcp.x());
  const double b = tcp.z() - arm.links[0].d;
  // The closed form assumes the wrist centre on the tool axis (the tool offset along the flange
  // z axis, as configured); L is its distance along that axis.
  const double L = -wrist_in_tool(arm).z();

  const double k = a * a + b * b + L * L;
  const double R = std::hypot(a, b);
  const double phi = std::atan2(b, a);
  const double straight = std::sqrt(a * a + (b + L) * (b + L));  // |w - s| at tilt = 0
  double tilt = 0;
  if (L > 0 && R > 0) {
    if (straight < settings.wrist_min) {
      tilt = tilt_for_distance(k, L, R, phi, settings.wrist_min);
    } else if (straight > settings.wrist_max) {
      tilt = tilt_for_distance(k, L, R, phi, settings.wrist_max);
    }
  }
  const double max_tilt = std::abs(settings.max_tilt);
  pose.tilt = std::clamp(tilt, -max_tilt, max_tilt);

  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(azimuth, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(kPi - pose.tilt, Eigen::Vector3d::UnitY()))
                                       .toRotationMatrix();
  pose.rpy = rpy_from_rotation(rotation);
  return pose;
}

Interception intercept(const ArmGeometry& arm, const PredictedPath& path, const Joints& current,
                       int64_t now, double lead_s, double after_start_s,
                       const Eigen::Vector3d& offset, double speed,
                       const InterceptionSettings& settings) {
  Interception out;
  if (path.lost) return fail(out, "the predictor has lost the track");
  if (path.points.empty()) return fail(out, "the predicted path is empty");
  if (!std::isfinite(lead_s) || !std::isfinite(after_start_s)) {
    return fail(out, "lead and after_start must be finite");
  }
  if (!(speed > 0 && speed <= 1)) return fail(out, "speed must be in (0, 1]");
  if (!offset.allFinite()) return fail(out, "offset is not finite");

  int64_t T = now + to_us(lead_s);
  for (int k = 0; k < std::max(settings.max_iterations, 1); ++k) {
    out.iterations = k + 1;
    out.arrival_utime = T;
    out.joints = Joints::Zero();  // set again once this iterate's IK succeeds
    const std::optional<Eigen::Vector3d> ball = path.at(T);
    if (!ball) {
      const bool late = T > path.end_utime();
      return fail(out, std::string(late ? "arrival beyond the prediction horizon"
                                        : "arrival before the predicted path begins") +
                           " (T - now = " + std::to_string((T - now) / 1000) + " ms)");
    }
    out.ball = *ball;
    const Eigen::Vector3d tcp = *ball + offset;
    out.pose = approach_pose(arm, tcp, settings);
    if (!(tcp.z() >= settings.table_z + settings.table_margin)) {
      return fail(out, "target below the table (tcp z = " + std::to_string(tcp.z()) + " m)");
    }
    if (!arm.workspace.contains(tcp)) return fail(out, "target outside the workspace");
    const IkResult ik =
        solve_nearest(arm, pose_from_xyz_rpy(out.pose.position, out.pose.rpy), current);
    if (!ik.joints) return fail(out, "target unreachable: " + ik.error);
    out.joints = *ik.joints;

    const double move = motion_time(arm, current, out.joints, speed);
    const int64_t next = now + to_us(lead_s + std::max(move, after_start_s));
    if (std::abs(next - T) < settings.tolerance_us) {
      out.ok = true;
      out.error.clear();
      return out;
    }
    T = next;
  }
  return fail(out, "did not converge in " + std::to_string(out.iterations) + " iterations");
}

}  // namespace sg::grasp
