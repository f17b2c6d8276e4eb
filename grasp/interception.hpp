#pragma once

/// Interception (issue 8, the reason the predictor exists): the controller answers one
/// interaction every 0.72-0.84 s, so a command must aim where the ball will be when the gripper
/// gets there. For a command sent at `now`, the arrival time T solves the fixed point
///
///     T = now + lead + max(motion_time(q_now -> IK(pose(p(T)))), after_start),
///
/// where p(t) is the predicted path (OBJECT_TRAJECTORY, interpolated), `lead` the controller's
/// delay before it acts, and `after_start` the time after the motion starts at which the gripper
/// acts (a CLOSE sent in the same interaction executes one delay later). It is iterated from
/// T0 = now + lead until it moves by less than a millisecond.
///
///     PredictedPath path = path_from(trajectory);
///     Interception aim = intercept(arm, path, q_now, now, 0.78, 0.0, {0, 0, 0.10}, 0.5, {});
///     if (aim.ok) send(aim.pose);          // 10 cm above where the ball will be at
///     aim.arrival_utime
///
/// Pure: no clock, no bus. Times in microseconds since the Unix epoch, lengths in metres.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "arm_driver/kinematics.hpp"

namespace sg::grasp {

using arm::ArmGeometry;
using arm::Joints;

/// The ball's predicted path: points[i] at start_utime + i * period_us (trajectory_t).
struct PredictedPath {
  int64_t utime = 0;            ///< the newest sample the prediction rests on
  int64_t start_utime = 0;      ///< time of points[0] (normally utime + period_us)
  int64_t period_us = 250'000;  ///< 4 Hz
  std::vector<Eigen::Vector3d> points;
  /// The 1-sigma error of each point per axis (trajectory_t.position_sigma), m: empty when the
  /// path's maker gave none, else as many as points.
  std::vector<Eigen::Vector3d> sigmas;
  bool lost = false;  ///< the predictor has lost the track: no target from this path

  /// A path that stays at `position` (the --no-prediction baseline: aim at the last measurement).
  static PredictedPath hold(const Eigen::Vector3d& position, int64_t utime,
                            int64_t period_us = 250'000, int count = 16);

  /// Time of the last point (start_utime when there is none).
  int64_t end_utime() const;

  /// The position at `t`: linear interpolation between the points; from utime to start_utime,
  /// the line through points[0] and points[1] extended back (points[0] when there is one point);
  /// nullopt before utime, after end_utime(), or for an empty or lost path.
  std::optional<Eigen::Vector3d> at(int64_t t) const;

  /// The 1-sigma error per axis at `t`: linear interpolation between the points' sigmas, and
  /// sigmas[0] from utime to start_utime (no extrapolation toward zero); nullopt where at() is,
  /// or when the path carries no sigmas.
  std::optional<Eigen::Vector3d> sigma_at(int64_t t) const;
};

/// Where the tool must go and how it is turned.
struct ApproachPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< tool centre point, base frame
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();       ///< fixed X-Y-Z angles (arm_cmd_t)
  double tilt = 0;  ///< rad from straight down, positive leaning outward (away from the base)
};

struct InterceptionSettings {
  double table_z = 0.0;        ///< table top in the base frame, m
  double table_margin = 0.05;  ///< the tool centre point stays this far above the table
  double wrist_min = 0.40;     ///< m: the wrist centre is kept this far from the shoulder ...
  double wrist_max = 0.60;     ///< ... and no farther (the A465 reaches 0.365 to 0.635)
  double max_tilt = 1.05;      ///< rad (60 deg): the steepest lean of the approach
  int max_iterations = 10;
  int64_t tolerance_us = 1000;  ///< the fixed point has converged when T moves less than this
};

/// The tool pointing down at `tcp`, square to the base (yaw = azimuth + pi, so joint 6 stays near
/// zero), leaned in the vertical plane through the base's axis by the smallest tilt that puts the
/// wrist centre between wrist_min and wrist_max from the shoulder (so the paper's whole circle is
/// reachable with one tool): with the wrist at w = tcp - L u, u the tool axis and L the flange's
/// d6 plus the tool offset, |w - shoulder| is solved in closed form for the tilt.
ApproachPose approach_pose(const ArmGeometry& arm, const Eigen::Vector3d& tcp,
                           const InterceptionSettings& settings);

/// The outcome of intercept(). ball, pose and joints all belong to arrival_utime (the last
/// iterate T_k, for which |F(T_k) - T_k| < tolerance_us when ok). When !ok the fields hold what
/// was computed before the refusal (arrival_utime and iterations always; ball and pose once the
/// path gave a position; joints once the inverse kinematics succeeded).
struct Interception {
  bool ok = false;
  std::string error;               ///< why not, when !ok (lost path, beyond the horizon, below the
                                   ///< table, outside the workspace, unreachable)
  ApproachPose pose;               ///< where to send the tool
  Joints joints = Joints::Zero();  ///< its inverse kinematics nearest the current joints
  Eigen::Vector3d ball = Eigen::Vector3d::Zero();  ///< the predicted ball centre at arrival
  int64_t arrival_utime = 0;                       ///< T
  int iterations = 0;  ///< evaluations of the right-hand side F(T) (1 = T0 converged)
};

/// Solves the fixed point above for a tool target at p(T) + offset (T rounded to microseconds,
/// at most settings.max_iterations evaluations). Refuses, in this order per iterate, a lost or
/// empty path, a speed outside (0, 1] or non-finite inputs, a T outside the path, a tool target
/// below table_z + table_margin, outside geometry.workspace, or without an IK solution within the
/// joint limits (solve_nearest from `current`), and "did not converge". `lead_s` and
/// `after_start_s` in seconds, `speed` the fraction of the joint speed limits (arm_cmd_t.speed).
Interception intercept(const ArmGeometry& arm, const PredictedPath& path, const Joints& current,
                       int64_t now, double lead_s, double after_start_s,
                       const Eigen::Vector3d& offset, double speed,
                       const InterceptionSettings& settings);

}  // namespace sg::grasp
