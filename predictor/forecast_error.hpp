#pragma once

/// The predictor's estimate of its own error, per horizon, from its past forecasts against what
/// came (issue 17: forecasts that know how sure they are).
///
/// Each forecast made at grid time T (after k fed-back samples at the end of its history) is
/// kept until its last point's time has passed. When a measured grid sample x(t) arrives, every
/// kept forecast whose point h was for t is scored: its error e = x(t) - x_hat(t) goes to the
/// estimate of horizon b = h + k, the samples since the last measurement that forecast rested on
/// (a forecast made 3 samples into an occlusion forecasts its first point 4 samples past what it
/// saw). Per horizon and axis the estimate is a mean square
///
///     s_b^2 <- s_b^2 + lambda (e^2 - r^2 - s_b^2),   lambda = max(1 / (n_b + 2), 1 / window)
///
/// (n_b the scores before this one): a running mean over the prior s_b = prior_sigma * b, which
/// counts as one score, and the first scores, then an exponential window of `window` scores.
/// r is the measured sample's own sigma (zero when not known): taken out, what is estimated is
/// the forecast's error against where the ball is, which a grasp needs, not against a noisy
/// measurement of it. sigma(b) is sqrt(max(s_b^2, 0)), at least min_sigma. The estimates survive
/// reset() (they describe the predictor on this motion, not one track); the kept forecasts do not
/// (their grid is gone).
///
///     ForecastError error(16, 16);                  // horizon H, max_gap: horizons 1 .. H + 16
///     error.score(sample_utime, sample);            // a measured grid sample, before ...
///     error.record(f.utime, f.occluded_samples, f.positions, period_us);   // ... its forecast
///     const Eigen::Vector3d s4 = error.sigma(4 + f.occluded_samples);      // 1 sigma, m
///
/// No allocation after construction; record and score are O(H) (at most H forecasts are kept,
/// one point each is scored), sigma O(1).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace sg::predictor {

struct ForecastErrorParams {
  double prior_sigma = 0.005;  ///< m per axis and sample of horizon, before any score
  int window = 200;            ///< scores the estimate averages once it has had that many
  double min_sigma = 1e-4;     ///< m: no horizon is ever surer than this
};

class ForecastError {
 public:
  /// `horizon`: points per forecast (H >= 1); `max_gap`: fed-back samples a forecast may rest on
  /// (>= 0). Horizons 1 .. horizon + max_gap are estimated. Throws std::invalid_argument on a
  /// horizon below 1, a negative max_gap, a window below 1 or a prior or floor not positive and
  /// finite.
  ForecastError(int horizon, int max_gap, const ForecastErrorParams& params = {});

  /// Keeps the forecast made at grid time `utime` (its point h for utime + h period_us) after
  /// `occluded` fed-back samples, for scoring. Points beyond the horizon it was built with and a
  /// forecast not after the last kept one are ignored; non-finite points are never scored.
  void record(int64_t utime, int occluded, const std::vector<Eigen::Vector3d>& positions,
              int64_t period_us);
  /// A measured grid sample at `utime`: scores the kept forecasts' points for that time, once (a
  /// time not after the last scored one scores nothing). A non-finite sample, and an error over
  /// 1e6 m, score nothing.
  /// `sample_sigma`: the sample's own 1-sigma error per axis (m), whose variance is taken out of
  /// each squared error, so the estimate is of the forecast's error against where the ball is,
  /// not against a noisy measurement of it (zero: none known).
  void score(int64_t utime, const Eigen::Vector3d& sample,
             const Eigen::Vector3d& sample_sigma = Eigen::Vector3d::Zero());
  /// Forgets the kept forecasts (a new track, a new grid); the estimates stay.
  void reset();

  /// 1-sigma error per axis (m) of a point `samples` grid samples past the last measurement
  /// (1 .. horizon + max_gap; clamped into that range).
  Eigen::Vector3d sigma(int samples) const;
  /// Scores the estimate of that horizon has had (0 .. ; the prior not counted).
  int64_t scores(int samples) const;
  int horizons() const { return static_cast<int>(mean_square_.size()); }

 private:
  struct Kept {
    int64_t utime = 0;
    int64_t period_us = 0;
    int occluded = 0;
    int points = 0;
    std::vector<Eigen::Vector3d> positions;  // capacity horizon, reserved once
  };
  size_t bucket(int samples) const;

  int horizon_;
  ForecastErrorParams params_;
  std::vector<Eigen::Vector3d> mean_square_;  // per horizon - 1
  std::vector<int64_t> scores_;
  std::vector<Kept> kept_;  // a ring of the last `horizon` forecasts
  size_t next_ = 0;         // where the next forecast goes
  size_t count_ = 0;        // forecasts held
  bool scored_ = false;     // last_scored_ is set
  int64_t last_scored_ = 0;
};

}  // namespace sg::predictor
