// How well each predictor forecasts the paper's motion (shared reference burg.md): a circle of
// 0.15 m at 1 rpm in the X-Y plane plus a Y drift of 0.01 m/s reversing every 20 s, sampled at
// 4 Hz with 1 mm of noise per axis; Burg trained offline on a pure-circle record, then adapted
// online. 3D RMS error against the true position at h = 1, 4 and 16 samples ahead; the pure circle
// at h = 16; and the fed-back samples through 16-sample (4 s) occlusions. Prints a table.
//
//   build/bin/predictor_accuracy
// Goals (issue 6), Burg: h = 1, 4, 16 at most 1.7, 4.5, 20 mm; pure circle h = 16 at most 3 mm;
// occlusion gaps at most 12 mm.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include "predictor/burg.hpp"
#include "predictor/trajectory_predictor.hpp"
#include "sim/scenario.hpp"

namespace {

using sg::predictor::Forecast;
using sg::predictor::Measurement;
using sg::predictor::Model;
using sg::predictor::PredictorParams;
using sg::predictor::TrajectoryPredictor;

constexpr int64_t kT0 = 1'700'000'000'000'000, kPeriod = 250'000;
constexpr int kWarmup = 480, kSamples = 480 + 4 * 2400;  // 2 min warm-up, then 40 min

struct Errors {
  double h1 = 0, h4 = 0, h16 = 0, gap = 0;
  /// Share of the true positions' coordinates within 2 sigma of the forecast (its own
  /// Forecast::sigma) at h = 1, 4, 16; and the mean sigma there, mm.
  std::array<double, 3> inside{0, 0, 0}, sigma{0, 0, 0};
};
constexpr std::array<int, 3> kHorizons{1, 4, 16};

std::unique_ptr<sg::sim::Scenario> motion(bool drift) {
  sg::sim::ScenarioParams p;
  p.kind = drift ? "paper" : "circle";
  p.phase = 0.3;
  return sg::sim::make_scenario(p);
}

/// Offline training (section 5.5): Burg on a noisy pure-circle record, mean removed, per axis.
std::array<std::vector<double>, 3> train(int order) {
  const auto circle = motion(false);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.001);
  std::array<std::vector<double>, 3> coefficients;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> x;
    for (int k = 0; k < 960; ++k) x.push_back(circle->position(k * 0.25)[axis] + noise(rng));
    double mean = 0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
    for (double& v : x) v -= mean;
    coefficients[static_cast<size_t>(axis)] =
        sg::predictor::burg(x.data(), static_cast<int>(x.size()), order).coefficients;
  }
  return coefficients;
}

/// Runs a predictor over the motion; with `occlusions`, one 16-sample gap in every 240 samples
/// (60 s), at an offset drawn uniformly from `gap_seed` (gaps at a fixed phase would all start on
/// a drift reversal, or never), and only the fed-back samples are scored.
Errors evaluate(const PredictorParams& params, bool drift, bool occlusions, unsigned gap_seed = 1) {
  const auto truth = motion(drift);
  TrajectoryPredictor predictor(params);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 0.001);
  std::mt19937 gap_rng(gap_seed);
  std::uniform_int_distribution<int> gap_offset(0, 240 - 16 - 1);
  int gap_start = -1;
  double s1 = 0, s4 = 0, s16 = 0, sg = 0;
  int n = 0, ng = 0;
  Errors e;
  for (int k = 0; k < kSamples; ++k) {
    const double t = k * 0.25;
    if (k % 240 == 0) gap_start = k + gap_offset(gap_rng);
    const bool hidden = occlusions && k >= kWarmup && k >= gap_start && k < gap_start + 16;
    const Eigen::Vector3d seen =
        truth->position(t) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const Eigen::Vector3d sigma = Eigen::Vector3d::Constant(0.001);  // the noise, as vision says
    for (const Forecast& f : predictor.add({kT0 + k * kPeriod, !hidden, seen, sigma})) {
      if (k < kWarmup || f.positions.size() < 16) continue;
      if (occlusions) {
        if (hidden) sg += (f.sample - truth->position(t)).squaredNorm(), ++ng;
        continue;
      }
      auto err = [&](int h) {
        return (f.positions[static_cast<size_t>(h - 1)] - truth->position(t + 0.25 * h))
            .squaredNorm();
      };
      s1 += err(1), s4 += err(4), s16 += err(16), ++n;
      for (size_t i = 0; i < kHorizons.size(); ++i) {
        const auto h = static_cast<size_t>(kHorizons[i] - 1);
        const Eigen::Vector3d d = f.positions[h] - truth->position(t + 0.25 * kHorizons[i]);
        for (int a = 0; a < 3; ++a) e.inside[i] += std::abs(d[a]) <= 2 * f.sigma[h][a];
        e.sigma[i] += f.sigma[h].mean();
      }
    }
  }
  for (size_t i = 0; i < kHorizons.size(); ++i) {
    e.inside[i] /= 3.0 * std::max(n, 1);
    e.sigma[i] *= 1e3 / std::max(n, 1);
  }
  e.h1 = std::sqrt(s1 / std::max(n, 1)) * 1e3;
  e.h4 = std::sqrt(s4 / std::max(n, 1)) * 1e3;
  e.h16 = std::sqrt(s16 / std::max(n, 1)) * 1e3;
  e.gap = std::sqrt(sg / std::max(ng, 1)) * 1e3;
  return e;
}

PredictorParams burg_params(int order) {
  PredictorParams p;
  p.model = Model::kBurg;
  p.burg.order = order;
  p.burg.window = 480;
  p.initial_coefficients = train(order);
  return p;
}

}  // namespace

int main() {
  PredictorParams hold;
  hold.model = Model::kHold;
  // The Kalman filter's process noise, tuned on this motion (its best h = 4 error).
  PredictorParams kalman;
  kalman.model = Model::kKalman;
  double best_q = 0, best = 1e9;
  for (double q : {1e-7, 3e-7, 1e-6, 3e-6, 1e-5, 3e-5, 1e-4}) {
    kalman.kalman.q = q;
    const double e = evaluate(kalman, true, false).h4;
    if (e < best) best = e, best_q = q;
  }
  kalman.kalman.q = best_q;
  const PredictorParams burg = burg_params(12);

  std::printf(
      "Paper's motion (circle 0.15 m at 1 rpm + Y drift 0.01 m/s reversing every 20 s), 4 Hz,\n"
      "1 mm noise per axis, 40 min after a 2 min warm-up; 3D RMS error against the truth, mm.\n\n");
  std::printf("%-34s %8s %8s %8s %14s %16s\n", "predictor", "h = 1", "h = 4", "h = 16",
              "circle h = 16", "occlusion gaps");
  struct Row {
    const char* name;
    PredictorParams params;
  };
  char kalman_name[64];
  std::snprintf(kalman_name, sizeof kalman_name, "Kalman, constant velocity (q %.0e)", best_q);
  std::vector<std::pair<const char*, Errors>> calibration;
  for (const Row& row : {Row{"Burg p = 12, W = 480, mean removed", burg}, Row{kalman_name, kalman},
                         Row{"hold last value", hold}}) {
    const Errors drift = evaluate(row.params, true, false);
    calibration.emplace_back(row.name, drift);
    const Errors circle = evaluate(row.params, false, false);
    // Gaps: 8 draws of 40 gaps each (320 in all); a gap that holds a drift reversal costs more,
    // so one draw alone varies by several millimetres.
    double pooled = 0, lo = 1e9, hi = 0;
    for (unsigned seed = 1; seed <= 8; ++seed) {
      const double g = evaluate(row.params, true, true, seed).gap;
      pooled += g * g / 8;
      lo = std::min(lo, g), hi = std::max(hi, g);
    }
    std::printf("%-34s %8.2f %8.2f %8.2f %14.2f %8.2f (%.1f-%.1f)\n", row.name, drift.h1, drift.h4,
                drift.h16, circle.h16, std::sqrt(pooled), lo, hi);
  }
  std::printf("\ngoals for Burg: %8.2f %8.2f %8.2f %14.2f %8.2f\n", 1.7, 4.5, 20.0, 3.0, 12.0);
  std::printf(
      "(occlusion gaps: RMS over 320 gaps of 16 samples, 8 draws of their places; the range "
      "is over the draws)\n");
  std::printf(
      "\nThe predictor's own error estimate (Forecast::sigma, per axis) on the same run: the "
      "share of\ntrue coordinates within 2 sigma of the forecast (goal 90-98%%), and the mean "
      "sigma, mm.\n\n");
  std::printf("%-34s %16s %16s %16s\n", "predictor", "h = 1", "h = 4", "h = 16");
  for (const auto& [name, e] : calibration) {
    std::printf("%-34s", name);
    for (size_t i = 0; i < kHorizons.size(); ++i)
      std::printf("   %5.1f%% (%5.2f)", 100 * e.inside[i], e.sigma[i]);
    std::printf("\n");
  }
  return 0;
}
