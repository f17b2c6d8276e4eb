#include "arm_driver/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace sg::arm {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadPerDeg = kPi / 180.0;   // configuration and the A465 table only
constexpr double kShoulderSingular = 1e-12;  // m: wrist centre this close to the waist axis
constexpr double kWristSingular = 1e-9;      // |sin q5| below this: wrist straight
constexpr double kReachSlack = 1e-12;        // relative: roundoff at full stretch
constexpr double kLimitSlack = 1e-9;         // rad: roundoff at a joint limit
constexpr double kSameSolution = 1e-12;      // rad: duplicates

/// The angle equivalent to `a` in (-pi, pi].
double wrap(double a) {
  double w = std::remainder(a, 2 * kPi);
  if (w <= -kPi) w += 2 * kPi;
  return w;
}

/// The sign of x as +-1 (for sin(alpha) = +-1 of a 90 degree twist).
double sign(double x) { return x < 0 ? -1.0 : 1.0; }

Eigen::Matrix3d rot_x(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }
Eigen::Matrix3d rot_y(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d rot_z(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }

bool near_abs_90deg(double alpha) { return std::abs(std::abs(alpha) - kPi / 2) < 1e-9; }

/// Joint angles q from DH thetas.
Joints joints_from_thetas(const ArmGeometry& g, const Joints& theta) {
  Joints q;
  for (int i = 0; i < 6; ++i) q[i] = wrap(theta[i] - g.links[i].theta_offset);
  return q;
}

/// theta_1 candidates for the wrist centre c (base frame): facing it, then reaching backwards.
std::vector<double> waist_thetas(const ArmGeometry& g, const Eigen::Vector3d& c, double hint) {
  const double lateral = -sign(std::sin(g.links[1].alpha)) * (g.links[1].d + g.links[2].d);
  const double rho2 = c.x() * c.x() + c.y() * c.y();
  const double radial2 = rho2 - lateral * lateral;
  const double scale = std::max(rho2, lateral * lateral);
  if (radial2 < -kReachSlack * scale) return {};
  if (lateral == 0 && std::sqrt(rho2) < kShoulderSingular) return {hint, hint + kPi};
  const double phi = std::atan2(c.y(), c.x());
  const double radial = std::sqrt(std::max(radial2, 0.0));
  return {phi - std::atan2(lateral, radial), phi - std::atan2(lateral, -radial)};
}

/// (theta_2, theta_3) pairs placing the wrist centre c given theta_1; see inverse_kinematics().
std::vector<std::array<double, 2>> arm_thetas(const ArmGeometry& g, const Eigen::Vector3d& c,
                                              double theta1) {
  const double s1 = -sign(std::sin(g.links[1].alpha));
  const double s3 = -sign(std::sin(g.links[3].alpha));
  const double a1 = g.links[1].a, a2 = g.links[2].a, a3 = g.links[3].a, d4 = g.links[3].d;
  // The wrist centre in the arm's plane: (px, py) = RotZ(theta_2) (X, Y) below, where px is its
  // radial distance beyond the shoulder offset a_1 and py = -s1 times its height above frame 1.
  const double px = std::cos(theta1) * c.x() + std::sin(theta1) * c.y() - a1;
  const double py = -s1 * (c.z() - g.links[0].d);
  const double R = std::hypot(a3, d4);
  const double cosine = (px * px + py * py - a2 * a2 - R * R) / (2 * a2 * R);
  if (std::abs(cosine) > 1 + kReachSlack) return {};
  const double psi = std::atan2(s3 * d4, a3);
  const double bend = std::acos(std::clamp(cosine, -1.0, 1.0));
  std::vector<std::array<double, 2>> out;
  for (const double theta3 : {bend - psi, -bend - psi}) {
    const double X = a2 + a3 * std::cos(theta3) - s3 * d4 * std::sin(theta3);
    const double Y = a3 * std::sin(theta3) + s3 * d4 * std::cos(theta3);
    out.push_back({std::atan2(py, px) - std::atan2(Y, X), theta3});
  }
  return out;
}

/// (theta_4, theta_5, theta_6) solutions of M = RotZ(t4) RotX(alpha_4) RotZ(t5) RotX(alpha_5)
/// RotZ(t6). Column 3 of M is (sa5 s5 c4, sa5 s5 s4, -sa4 sa5 c5).
std::vector<Eigen::Vector3d> wrist_thetas(const ArmGeometry& g, const Eigen::Matrix3d& M,
                                          double theta4_hint) {
  const double sa4 = sign(std::sin(g.links[4].alpha));
  const double sa5 = sign(std::sin(g.links[5].alpha));
  const Eigen::Vector3d v = M.col(2);
  const double c5 = -sa4 * sa5 * v.z();
  const double h = std::hypot(v.x(), v.y());
  std::vector<double> theta4s;
  if (h < kWristSingular) {
    theta4s = {theta4_hint};
  } else {
    const double t4 = std::atan2(sa5 * v.y(), sa5 * v.x());
    theta4s = {t4, t4 + kPi};
  }
  std::vector<Eigen::Vector3d> out;
  for (const double t4 : theta4s) {
    const double s5 = sa5 * (std::cos(t4) * v.x() + std::sin(t4) * v.y());
    const double t5 = std::atan2(s5, c5);
    const Eigen::Matrix3d N =
        (rot_z(t4) * rot_x(g.links[4].alpha) * rot_z(t5) * rot_x(g.links[5].alpha)).transpose() * M;
    out.emplace_back(t4, t5, std::atan2(N(1, 0), N(0, 0)));
  }
  return out;
}

/// All solutions; `hint` supplies q1 and q4 at the singularities.
std::vector<Joints> solve_all(const ArmGeometry& g, const Eigen::Isometry3d& tcp,
                              const Joints& hint) {
  const Eigen::Isometry3d flange = tcp * g.tool.inverse();
  const Eigen::Matrix3d R06 = flange.linear();
  const Eigen::Vector3d centre = flange.translation() - g.links[5].d * R06.col(2);
  std::vector<Joints> solutions;
  for (const double t1 : waist_thetas(g, centre, hint[0] + g.links[0].theta_offset)) {
    for (const auto& [t2, t3] : arm_thetas(g, centre, t1)) {
      Joints theta = Joints::Zero();
      theta.head<3>() << t1, t2, t3;
      Eigen::Matrix3d R03 = Eigen::Matrix3d::Identity();
      for (int i = 0; i < 3; ++i) R03 = R03 * rot_x(g.links[i].alpha) * rot_z(theta[i]);
      const Eigen::Matrix3d M = (R03 * rot_x(g.links[3].alpha)).transpose() * R06;
      for (const Eigen::Vector3d& w : wrist_thetas(g, M, hint[3] + g.links[3].theta_offset)) {
        theta.tail<3>() = w;
        const Joints q = joints_from_thetas(g, theta);
        const bool seen = std::any_of(solutions.begin(), solutions.end(), [&](const Joints& s) {
          return (s - q).unaryExpr(&wrap).cwiseAbs().maxCoeff() < kSameSolution;
        });
        if (!seen) solutions.push_back(q);
      }
    }
  }
  return solutions;
}

/// Per-joint time at full speed, seconds.
Eigen::Matrix<double, 6, 1> joint_times(const ArmGeometry& g, const Joints& from,
                                        const Joints& to) {
  Eigen::Matrix<double, 6, 1> t;
  for (int i = 0; i < 6; ++i) t[i] = std::abs(to[i] - from[i]) / g.links[i].max_speed;
  return t;
}

/// The 2 pi equivalent of q within [min, max] (with slack, then clamped) nearest to `current`,
/// or nothing when none is within the limits.
std::optional<double> nearest_in_limits(const DhLink& link, double q, double current) {
  std::optional<double> best;
  const double lo = link.min - kLimitSlack, hi = link.max + kLimitSlack;
  for (double k = std::ceil((lo - q) / (2 * kPi)); q + 2 * kPi * k <= hi; ++k) {
    const double candidate = std::clamp(q + 2 * kPi * k, link.min, link.max);
    if (!best || std::abs(candidate - current) < std::abs(*best - current)) best = candidate;
  }
  return best;
}

}  // namespace

bool Workspace::contains(const Eigen::Vector3d& p) const {
  return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
}

ArmGeometry ArmGeometry::a465() {
  // {alpha deg, a m, d m, offset deg, limit deg, speed deg/s}; the limits are symmetric.
  constexpr double kTable[6][6] = {
      {0, 0, 0.330, 0, 175, 180},   {-90, 0, 0, -90, 90, 180}, {0, 0.305, 0, -90, 110, 180},
      {-90, 0, 0.330, 0, 180, 171}, {90, 0, 0, 0, 105, 173},   {-90, 0, 0.076, 180, 180, 171},
  };
  ArmGeometry g;
  for (int i = 0; i < 6; ++i) {
    const double* r = kTable[i];
    g.links[i] = {
        r[0] * kRadPerDeg, r[1], r[2], r[3] * kRadPerDeg, -r[4] * kRadPerDeg, r[4] * kRadPerDeg,
        r[5] * kRadPerDeg};
  }
  g.tool = Eigen::Translation3d(0, 0, 0.15);
  g.workspace.min = {-0.90, -0.90, 0.05};
  g.workspace.max = {0.90, 0.90, 1.25};
  return g;
}

Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rot_z(rpy.z()) * rot_y(rpy.y()) * rot_x(rpy.x());
  pose.translation() = xyz;
  return pose;
}

Eigen::Vector3d rpy_from_rotation(const Eigen::Matrix3d& R) {
  const double cos_pitch = std::hypot(R(0, 0), R(1, 0));
  if (cos_pitch >= 1e-10) {
    return {std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), cos_pitch),
            std::atan2(R(1, 0), R(0, 0))};
  }
  // Gimbal lock: yaw = 0, so R = Ry(pitch) Rx(roll) and Ry(pitch)^T R = Rx(roll).
  const double pitch = R(2, 0) < 0 ? kPi / 2 : -kPi / 2;
  const Eigen::Matrix3d Rx = rot_y(pitch).transpose() * R;
  return {std::atan2(Rx(2, 1), Rx(1, 1)), pitch, 0.0};
}

Eigen::Isometry3d dh_transform(const DhLink& link, double q) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rot_x(link.alpha) * rot_z(q + link.theta_offset);
  T.translation() = rot_x(link.alpha) * Eigen::Vector3d(link.a, 0, 0) + T.linear().col(2) * link.d;
  return T;
}

Eigen::Isometry3d flange_pose(const ArmGeometry& geometry, const Joints& q) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 6; ++i) T = T * dh_transform(geometry.links[i], q[i]);
  return T;
}

Eigen::Isometry3d forward_kinematics(const ArmGeometry& geometry, const Joints& q) {
  return flange_pose(geometry, q) * geometry.tool;
}

std::vector<Joints> inverse_kinematics(const ArmGeometry& geometry, const Eigen::Isometry3d& tcp) {
  return solve_all(geometry, tcp, Joints::Zero());
}

std::string ik_structure_problem(const std::array<DhLink, 6>& l) {
  if (l[0].alpha != 0 || l[0].a != 0) return "row 1 must have alpha = 0 and a = 0";
  if (!near_abs_90deg(l[1].alpha)) return "row 2 must have alpha = +-90";
  if (l[2].alpha != 0 || !(l[2].a > 0)) return "row 3 must have alpha = 0 and a > 0";
  for (int i = 3; i < 6; ++i) {
    if (!near_abs_90deg(l[i].alpha))
      return "row " + std::to_string(i + 1) + " must have alpha = +-90";
  }
  if (l[4].a != 0 || l[4].d != 0 || l[5].a != 0) {
    return "rows 5 and 6 must have a = 0 and row 5 d = 0 (a spherical wrist)";
  }
  return "";
}

bool within_limits(const ArmGeometry& geometry, const Joints& q) {
  for (int i = 0; i < 6; ++i) {
    if (!(q[i] >= geometry.links[i].min && q[i] <= geometry.links[i].max)) return false;
  }
  return true;
}

IkResult solve_nearest(const ArmGeometry& geometry, const Eigen::Isometry3d& tcp,
                       const Joints& current) {
  if (!tcp.matrix().allFinite()) return {std::nullopt, "target pose is not finite"};
  if (!current.allFinite()) return {std::nullopt, "current joints are not finite"};
  if (!geometry.workspace.contains(tcp.translation()))
    return {std::nullopt, "outside the workspace"};
  const std::vector<Joints> solutions = solve_all(geometry, tcp, current);
  if (solutions.empty()) return {std::nullopt, "out of reach"};

  std::optional<Joints> best;
  double best_max = 0, best_sum = 0;
  int fewest_violations = 7, violated_joint = 0;
  for (const Joints& s : solutions) {
    Joints q;
    int violations = 0, first = 0;
    for (int i = 0; i < 6; ++i) {
      const std::optional<double> qi = nearest_in_limits(geometry.links[i], s[i], current[i]);
      if (!qi && violations++ == 0) first = i + 1;
      q[i] = qi.value_or(s[i]);
    }
    if (violations > 0) {
      if (violations < fewest_violations) fewest_violations = violations, violated_joint = first;
      continue;
    }
    const auto t = joint_times(geometry, current, q);
    if (!best || t.maxCoeff() < best_max || (t.maxCoeff() == best_max && t.sum() < best_sum)) {
      best = q, best_max = t.maxCoeff(), best_sum = t.sum();
    }
  }
  if (!best)
    return {std::nullopt, "outside joint limits (joint " + std::to_string(violated_joint) + ")"};
  return {best, ""};
}

double motion_time(const ArmGeometry& geometry, const Joints& from, const Joints& to,
                   double speed_fraction) {
  if (!(speed_fraction > 0 && speed_fraction <= 1)) {
    throw std::invalid_argument("motion_time: speed_fraction must be in (0, 1]");
  }
  return joint_times(geometry, from, to).maxCoeff() / speed_fraction;
}

namespace {

/// The list of `n` rows of `width` numbers at `key` (which must be present), each finite and at
/// most `bound` in magnitude.
std::vector<std::vector<double>> read_rows(const sg::Config& config, const std::string& key,
                                           std::size_t n, std::size_t width,
                                           const std::string& shape, double bound) {
  const auto rows = config.require<std::vector<std::vector<double>>>(key);
  if (rows.size() != n) {
    throw config.error_at(key, "expected " + std::to_string(n) + " rows " + shape + ", got " +
                                   std::to_string(rows.size()));
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (rows[i].size() != width) {
      throw config.error_at(key, "row " + std::to_string(i + 1) + " must be " + shape + ", got " +
                                     std::to_string(rows[i].size()) + " numbers");
    }
    for (const double v : rows[i]) {
      if (!sg::Range::closed(-bound, bound).contains(v)) {
        throw config.error_at(key, "row " + std::to_string(i + 1) + ": every number must be in [" +
                                       sg::show(-bound) + ", " + sg::show(bound) + "], got " +
                                       sg::show(v));
      }
    }
  }
  return rows;
}

}  // namespace

ArmGeometry load_arm_geometry(const sg::Config& config) {
  ArmGeometry g = ArmGeometry::a465();
  sg::Section arm(config, "arm");
  arm.known("dh", "the A465's", "modified DH rows [alpha_deg, a_m, d_m, theta_offset_deg]");
  arm.known("limits_deg", "the A465's", "joint limits [[min_deg, max_deg] x 6]");
  std::vector<double> speeds_deg;
  for (const DhLink& l : g.links) speeds_deg.push_back(l.max_speed / kRadPerDeg);
  arm.numbers("max_speed_deg_s", speeds_deg.data(), 6, sg::Range::above_to(0, 3600),
              "joint speed limits, deg/s");
  Eigen::Vector3d tool = g.tool.translation();
  arm.numbers("tool_offset", tool.data(), 3, sg::Range::closed(-2, 2),
              "TCP in the flange frame, m");
  arm.numbers("workspace_min", g.workspace.min.data(), 3, sg::Range::closed(-10, 10),
              "the workspace's lower corner, m");
  arm.numbers("workspace_max", g.workspace.max.data(), 3, sg::Range::closed(-10, 10),
              "the workspace's upper corner, m");
  arm.done();
  if (config.has("arm.dh")) {
    const auto rows =
        read_rows(config, "arm.dh", 6, 4, "[alpha_deg, a_m, d_m, theta_offset_deg]", 360);
    for (int i = 0; i < 6; ++i) {
      DhLink& l = g.links[i];
      l.alpha = rows[i][0] * kRadPerDeg, l.a = rows[i][1], l.d = rows[i][2];
      l.theta_offset = rows[i][3] * kRadPerDeg;
    }
    const std::string problem = ik_structure_problem(g.links);
    if (!problem.empty()) throw config.error_at("arm.dh", problem);
  }
  if (config.has("arm.limits_deg")) {
    const auto rows = read_rows(config, "arm.limits_deg", 6, 2, "[min_deg, max_deg]", 360);
    for (int i = 0; i < 6; ++i) {
      if (!(rows[i][0] < rows[i][1])) {
        throw config.error_at("arm.limits_deg",
                              "row " + std::to_string(i + 1) + ": min must be below max");
      }
      g.links[i].min = rows[i][0] * kRadPerDeg, g.links[i].max = rows[i][1] * kRadPerDeg;
    }
  }
  for (int i = 0; i < 6; ++i) g.links[i].max_speed = speeds_deg[i] * kRadPerDeg;
  g.tool = Eigen::Translation3d(tool);
  if (!(g.workspace.min.array() < g.workspace.max.array()).all()) {
    throw config.error_at(
        config.has("arm.workspace_max") ? "arm.workspace_max" : "arm.workspace_min",
        "workspace_min must be below workspace_max on every axis");
  }
  return g;
}

}  // namespace sg::arm
