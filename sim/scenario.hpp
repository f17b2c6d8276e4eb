#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace sg::sim {

/// Parameters of a ball motion; metres, seconds, robot base frame. Everything a scenario does is
/// a function of these and of the time, so the same parameters and seed give the same path.
struct ScenarioParams {
  /// paper, circle, line, figure8, random or still.
  std::string kind = "paper";
  /// Centre of the motion.
  Eigen::Vector3d centre{0.45, 0.0, 0.10};
  /// Radius of the circle (paper, circle) or half-size of the figure eight.
  double radius = 0.15;
  /// Revolutions per minute (paper, circle, figure8); the paper's ball turns at 1 rpm.
  double rpm = 1.0;
  /// Angle of the ball on its circle at t = 0, radians; NaN draws it from the seed.
  double phase = std::numeric_limits<double>::quiet_NaN();
  /// paper: speed of the back-and-forth drift along Y (m/s) and the time between reversals (s).
  double drift_speed = 0.01;
  double drift_half_period = 20.0;
  /// line: unit direction, half-length (m) and speed (m/s) of a back-and-forth run.
  Eigen::Vector3d line_direction{0.0, 1.0, 0.0};
  double line_half_length = 0.15;
  double line_speed = 0.05;
  /// random: extent (m, per axis half-size in X, Y; a third of it in Z) and typical speed (m/s).
  double random_extent = 0.15;
  double random_speed = 0.05;
  /// Seed for everything drawn at random.
  uint64_t seed = 1;
};

/// A ball motion: the ball's centre at scenario time t (seconds from the scenario's start).
///
///     auto scenario = sg::sim::make_scenario({.kind = "paper"});
///     Eigen::Vector3d p = scenario->position(12.5);
class Scenario {
 public:
  virtual ~Scenario() = default;
  virtual Eigen::Vector3d position(double t) const = 0;
};

/// Builds the scenario named by params.kind; throws std::invalid_argument for an unknown kind or
/// a parameter out of range.
std::unique_ptr<Scenario> make_scenario(const ScenarioParams& params);

/// The names make_scenario accepts.
std::vector<std::string> scenario_kinds();

/// The paper's drift: a triangle wave that starts at 0 moving forward at `speed`, reverses every
/// `half_period` seconds (first at half_period / 2) and stays within +-speed * half_period / 2.
double triangle_drift(double t, double speed, double half_period);

}  // namespace sg::sim
