#pragma once

/// Kinematics of a six-axis articulated arm with a spherical wrist (the CRS A465 by default, see
/// the shared reference crs-arm.md): forward kinematics, closed-form inverse kinematics, joint
/// limits, a workspace box, joint-move timing, and loading the geometry from configuration.
///
/// Frames and units: metres and radians; the robot base frame has X forward, Y left, Z up, its
/// origin on the waist axis in the base's mounting plane. Frame i is attached to link i by the
/// modified (Craig) Denavit-Hartenberg convention
///
///   T_{i-1,i} = RotX(alpha_{i-1}) TransX(a_{i-1}) RotZ(theta_i) TransZ(d_i),
///   theta_i   = q_i + offset_i,
///
/// so the flange (frame 6) is T_06 = T_01 T_12 ... T_56 and the tool centre point (TCP) is
/// T_06 * tool. With the A465 table, q = 0 is the arm standing straight up (the "candle"):
/// flange at z = 0.330 + 0.305 + 0.330 + 0.076 m with the base's orientation (the 180 deg
/// offset of joint 6 makes R_06(0) = I), so the default TCP is at (0, 0, 1.191) m.
///
///     const sg::arm::ArmGeometry arm = sg::arm::ArmGeometry::a465();
///     const Eigen::Isometry3d grasp =
///         sg::arm::pose_from_xyz_rpy({0.45, 0.0, 0.10}, {std::numbers::pi, 0.0, 0.0});  // down
///     sg::arm::IkResult ik = sg::arm::solve_nearest(arm, grasp, current_joints);
///     if (!ik.joints) return fail(ik.error);   // "out of reach", "outside the workspace", ...
///     double seconds = sg::arm::motion_time(arm, current_joints, *ik.joints, 0.5);

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "common/config.hpp"

namespace sg::arm {

/// Joint angles q_1 .. q_6, radians (before the DH theta offsets are added).
using Joints = Eigen::Matrix<double, 6, 1>;

/// One row of the modified DH table (alpha_{i-1}, a_{i-1}, d_i, offset_i) and joint i's limits.
struct DhLink {
  double alpha = 0;         ///< alpha_{i-1}, rad: twist about x_{i-1}
  double a = 0;             ///< a_{i-1}, m: distance along x_{i-1}
  double d = 0;             ///< d_i, m: distance along z_i
  double theta_offset = 0;  ///< rad: theta_i = q_i + theta_offset
  double min = 0;           ///< lowest q_i, rad
  double max = 0;           ///< highest q_i, rad
  double max_speed = 0;     ///< rad/s, at 100% speed
};

/// An axis-aligned box, in the base frame, that the tool centre point must stay in. The default
/// box is unbounded.
struct Workspace {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  /// True when min <= p <= max on every axis (so false for a NaN).
  bool contains(const Eigen::Vector3d& p) const;
};

/// The arm: its DH table with limits and speeds, the tool, and the allowed TCP box.
struct ArmGeometry {
  std::array<DhLink, 6> links;
  Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();  ///< flange (frame 6) -> TCP
  Workspace workspace;

  /// The CRS A465 (crs-arm.md): lengths 330, 305, 330, 76 mm; limits +-175, +-90, +-110, +-180,
  /// +-105, +-180 deg; speeds 180, 180, 180, 171, 173, 171 deg/s. Tool: the gripper's TCP
  /// 0.15 m along the flange z axis. Workspace: x, y in [-0.90, 0.90] m, just beyond the TCP's
  /// reach (0.861 m from the waist axis), and z in [0.05, 1.25] m: a guard that keeps the TCP
  /// (and the finger tips a few cm beyond it) off the mounting table at z = 0 and that contains
  /// the zero pose (TCP at z = 1.191 m). A lab narrows it to its own table in configuration.
  static ArmGeometry a465();
};

/// The pose with position `xyz` (m) and fixed X-Y-Z angles `rpy` = (roll, pitch, yaw) (rad):
/// R = Rz(yaw) Ry(pitch) Rx(roll). rpy = (pi, 0, 0) points the tool z axis straight down.
Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy);

/// (roll, pitch, yaw) with R = Rz(yaw) Ry(pitch) Rx(roll); pitch in [-pi/2, pi/2], roll and yaw
/// in [-pi, pi]. At gimbal lock (|cos pitch| < 1e-10, where only roll -+ yaw is defined) it
/// returns pitch = +-pi/2, yaw = 0 and the roll that reproduces R.
Eigen::Vector3d rpy_from_rotation(const Eigen::Matrix3d& R);

/// T_{i-1,i} = RotX(alpha_{i-1}) TransX(a_{i-1}) RotZ(q_i + offset_i) TransZ(d_i).
Eigen::Isometry3d dh_transform(const DhLink& link, double q);

/// Base -> flange (frame 6): T_06(q).
Eigen::Isometry3d flange_pose(const ArmGeometry& geometry, const Joints& q);

/// Base -> tool centre point: T_06(q) * tool.
Eigen::Isometry3d forward_kinematics(const ArmGeometry& geometry, const Joints& q);

/// Every closed-form solution q with forward_kinematics(q) = tcp, angles wrapped to (-pi, pi],
/// NOT filtered by the joint limits; empty when the wrist centre is out of reach.
///
/// The wrist centre c = p_flange - d_6 z_flange (joints 4-6 meet there) depends on q1-q3 only:
///  - waist: in the waist-rotated frame the wrist centre's lateral coordinate must equal
///    D = -sin(alpha_1) (d_2 + d_3), so rho sin(phi - theta_1) = D with (rho, phi) the polar
///    coordinates of c in the XY plane: theta_1 = phi - atan2(D, +-sqrt(rho^2 - D^2))
///    (facing the target first, then reaching over backwards);
///  - elbow: in the arm's plane the shoulder-to-wrist distance fixes
///    a_3 cos(theta_3) - s d_4 sin(theta_3) = R cos(theta_3 + psi) = K, s = -sin(alpha_3),
///    R = hypot(a_3, d_4), psi = atan2(s d_4, a_3): two roots, theta_3 + psi >= 0 first (on the
///    A465 that is q3 >= 0, elbow up when the waist faces the target); theta_2 follows by atan2;
///  - wrist: M = (R_03 RotX(alpha_3))^T R_06 = RotZ(theta_4) RotX(alpha_4) RotZ(theta_5)
///    RotX(alpha_5) RotZ(theta_6); its third column gives theta_5 and theta_4 (two solutions,
///    sin(theta_5) >= 0 first, and the flip theta_4 + pi, -theta_5), the rest gives theta_6.
/// Singular cases are resolved deterministically: with the wrist centre on the waist axis
/// (D = 0, rho < 1e-12 m) q1 = 0 and q1 = pi; with the wrist straight (|sin q5| < 1e-9) a
/// single wrist solution with q4 = 0. Duplicate solutions are removed. Up to 8 solutions.
/// The geometry must satisfy ik_structure_problem() == "" (the A465 does).
std::vector<Joints> inverse_kinematics(const ArmGeometry& geometry, const Eigen::Isometry3d& tcp);

/// An empty string when the DH table has the structure inverse_kinematics() solves (alpha_0 = 0,
/// a_0 = 0, |alpha_1| = 90 deg, alpha_2 = 0, a_2 > 0, |alpha_3| = |alpha_4| = |alpha_5| = 90 deg,
/// a_4 = a_5 = d_5 = 0: a spherical wrist); otherwise what is wrong.
std::string ik_structure_problem(const std::array<DhLink, 6>& links);

/// True when every min_i <= q_i <= max_i (exactly; false for NaN).
bool within_limits(const ArmGeometry& geometry, const Joints& q);

/// A solution chosen by solve_nearest(), or why there is none.
struct IkResult {
  std::optional<Joints> joints;
  std::string error;  ///< empty when joints is set
};

/// The inverse-kinematics solution within the joint limits that the arm reaches soonest from
/// `current`: it minimises the time of the synchronous joint move, max_i |q_i - current_i| /
/// max_speed_i (ties broken by the sum of those per-joint times), over every solution and, per
/// joint, every 2 pi equivalent of q_i within the limits. Angles within 1e-9 rad of a limit
/// count as within and are clamped onto it, so the result always passes within_limits(). At
/// the singularities the free joint keeps its current value (q4 at the wrist, q1 on the waist
/// axis). Checks in this order, the error naming the first that fails:
///   "target pose is not finite" / "current joints are not finite",
///   "outside the workspace" (the TCP is not in geometry.workspace),
///   "out of reach" (no solution at all),
///   "outside joint limits (joint N)" (N = 1..6: the first joint out of limits in the solution
///   that violates the fewest joints).
IkResult solve_nearest(const ArmGeometry& geometry, const Eigen::Isometry3d& tcp,
                       const Joints& current);

/// Seconds for a synchronous joint move from `from` to `to` (all joints start and stop together,
/// the slowest at speed_fraction of its max speed; acceleration ignored):
/// max_i |to_i - from_i| / (speed_fraction * max_speed_i). Throws std::invalid_argument unless
/// 0 < speed_fraction <= 1.
double motion_time(const ArmGeometry& geometry, const Joints& from, const Joints& to,
                   double speed_fraction);

/// The geometry under "arm." in `config`, each key defaulting to ArmGeometry::a465():
///   arm.dh:              6 rows [alpha_deg, a_m, d_m, theta_offset_deg] (modified DH)
///   arm.limits_deg:      6 rows [min_deg, max_deg]
///   arm.max_speed_deg_s: 6 numbers
///   arm.tool_offset:     [x, y, z] metres, TCP in the flange frame
///   arm.workspace_min, arm.workspace_max: [x, y, z] metres, base frame
/// Degrees are converted to radians here. Throws sg::ConfigError naming the key for a list of
/// the wrong length, a non-finite number, min >= max, a speed <= 0, or a DH table that
/// inverse_kinematics() cannot solve.
ArmGeometry load_arm_geometry(const sg::Config& config);

}  // namespace sg::arm
