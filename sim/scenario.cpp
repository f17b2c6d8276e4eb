#include "sim/scenario.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace sg::sim {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

double angular_speed(const ScenarioParams& p) { return kTwoPi * p.rpm / 60.0; }

double initial_phase(const ScenarioParams& p) {
  if (std::isfinite(p.phase)) return p.phase;
  std::mt19937_64 rng(p.seed);
  return std::uniform_real_distribution<double>(0.0, kTwoPi)(rng);
}

/// The paper's motion: a horizontal circle plus a drift along Y (section 7).
class PaperScenario : public Scenario {
 public:
  explicit PaperScenario(const ScenarioParams& p)
      : p_(p), omega_(angular_speed(p)), phase_(initial_phase(p)) {}
  Eigen::Vector3d position(double t) const override {
    const double a = omega_ * t + phase_;
    return p_.centre + Eigen::Vector3d(p_.radius * std::cos(a),
                                       p_.radius * std::sin(a) +
                                           triangle_drift(t, p_.drift_speed, p_.drift_half_period),
                                       0.0);
  }

 private:
  ScenarioParams p_;
  double omega_, phase_;
};

class FigureEightScenario : public Scenario {
 public:
  explicit FigureEightScenario(const ScenarioParams& p)
      : p_(p), omega_(angular_speed(p)), phase_(initial_phase(p)) {}
  Eigen::Vector3d position(double t) const override {  // lemniscate of Gerono
    const double a = omega_ * t + phase_;
    return p_.centre + Eigen::Vector3d(p_.radius * std::cos(a), p_.radius * std::sin(2 * a) / 2, 0);
  }

 private:
  ScenarioParams p_;
  double omega_, phase_;
};

class LineScenario : public Scenario {
 public:
  explicit LineScenario(const ScenarioParams& p) : p_(p), u_(p.line_direction.normalized()) {}
  Eigen::Vector3d position(double t) const override {
    return p_.centre +
           u_ * triangle_drift(t, p_.line_speed, 2 * p_.line_half_length / p_.line_speed);
  }

 private:
  ScenarioParams p_;
  Eigen::Vector3d u_;
};

/// Smooth and bounded: per axis a sum of sinusoids with frequencies, amplitudes and phases drawn
/// from the seed, scaled so the typical speed is random_speed.
class RandomScenario : public Scenario {
 public:
  explicit RandomScenario(const ScenarioParams& p) : p_(p) {
    std::mt19937_64 rng(p.seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int axis = 0; axis < 3; ++axis) {
      const double extent = axis == 2 ? p.random_extent / 3 : p.random_extent;
      for (auto& w : waves_[axis]) {
        w.amplitude = extent / kWaves * (0.5 + unit(rng));
        // speed of one wave ~ amplitude * omega; share random_speed among the waves
        w.omega = p.random_speed / (w.amplitude * kWaves) * (0.5 + unit(rng));
        w.phase = kTwoPi * unit(rng);
      }
    }
  }
  Eigen::Vector3d position(double t) const override {
    Eigen::Vector3d offset = Eigen::Vector3d::Zero();
    for (int axis = 0; axis < 3; ++axis) {
      for (const auto& w : waves_[axis])
        offset[axis] += w.amplitude * std::sin(w.omega * t + w.phase);
    }
    return p_.centre + offset;
  }

 private:
  static constexpr int kWaves = 3;
  struct Wave {
    double amplitude, omega, phase;
  };
  ScenarioParams p_;
  Wave waves_[3][kWaves];
};

class CircleScenario : public PaperScenario {
 public:
  explicit CircleScenario(ScenarioParams p) : PaperScenario(without_drift(p)) {}

 private:
  static ScenarioParams without_drift(ScenarioParams p) {
    p.drift_speed = 0.0;
    return p;
  }
};

class StillScenario : public Scenario {
 public:
  explicit StillScenario(const ScenarioParams& p) : centre_(p.centre) {}
  Eigen::Vector3d position(double) const override { return centre_; }

 private:
  Eigen::Vector3d centre_;
};

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("scenario: " + what);
}

}  // namespace

double triangle_drift(double t, double speed, double half_period) {
  if (speed == 0.0) return 0.0;
  const double sweep = speed * half_period;  // from one extreme to the other
  double u = std::fmod(speed * t + sweep / 2, 2 * sweep);
  if (u < 0) u += 2 * sweep;
  return (u < sweep ? u : 2 * sweep - u) - sweep / 2;
}

std::vector<std::string> scenario_kinds() {
  return {"paper", "circle", "line", "figure8", "random", "still"};
}

std::unique_ptr<Scenario> make_scenario(const ScenarioParams& p) {
  check(p.centre.allFinite(), "centre must be finite");
  check(std::isfinite(p.radius) && p.radius >= 0, "radius must be a non-negative number");
  check(std::isfinite(p.rpm), "rpm must be a number");
  check(std::isfinite(p.drift_speed) && p.drift_speed >= 0, "drift_speed must be >= 0");
  check(p.drift_half_period > 0, "drift_half_period must be positive");
  if (p.kind == "paper") return std::make_unique<PaperScenario>(p);
  if (p.kind == "circle") return std::make_unique<CircleScenario>(p);
  if (p.kind == "figure8") return std::make_unique<FigureEightScenario>(p);
  if (p.kind == "line") {
    check(p.line_direction.norm() > 0, "line_direction must not be zero");
    check(p.line_speed > 0 && p.line_half_length > 0,
          "line_speed and line_half_length must be > 0");
    return std::make_unique<LineScenario>(p);
  }
  if (p.kind == "random") {
    check(p.random_extent > 0 && p.random_speed > 0, "random_extent and random_speed must be > 0");
    return std::make_unique<RandomScenario>(p);
  }
  if (p.kind == "still") return std::make_unique<StillScenario>(p);
  std::string kinds;
  for (const auto& k : scenario_kinds()) kinds += (kinds.empty() ? "" : ", ") + k;
  throw std::invalid_argument("scenario: unknown kind '" + p.kind + "' (one of " + kinds + ")");
}

}  // namespace sg::sim
