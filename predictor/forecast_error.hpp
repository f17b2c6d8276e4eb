#pragma once

/// The predictor's estimate of its own error, per horizon, from its past forecasts against what
/// came (issue 17: forecasts that know how sure they are).
///
/// Each forecast made at grid time T (after k fed-back samples at the end of its history) is
/// kept until its last point's time has passed. When a measured grid sample x(t) arrives, every
/// kept forecast whose point h was for t is scored: its error e = x(t) - x_hat(t) goes to the
/// estimate of horizon b = h + k, the samples since the last measurement that forecast rested on
/// (a forecast made 3 samples into an occlusion forecasts its first point 4 samples past what it
/// saw). Per horizon and axis the estimate is the mean square over a sliding window of the last
/// `window` scores,
///
///     s_b^2 = (1 / m) sum over the last m scores of (e^2 - r^2),   m = min(n_b + 1, window)
///
/// where the prior (prior_sigma * b)^2 is the first score, so it counts until `window` real
/// ones have followed. A sliding window, not an exponential one: the start-up's errors (a model
/// not yet fitted, 10-100 times the error it settles to) and a turn's are forgotten entirely
/// `window` scores later (15 s at 4 Hz with the default 60), where an exponential average keeps a
/// share of them for minutes. The share of true positions within 2 sigma on the paper's motion
/// is then 91-95% (40 scores: 90-93%; 80, the paper's 20 s drift period: the estimate clears of
/// one reversal just as the next comes; docs/prediction.md). sigma() is widened by
/// predictive_factor() (Student's t for the m scores) unless params.predictive is false.
/// r is the measured sample's own sigma (zero when not known): taken out, what is estimated is
/// the forecast's error against where the ball is, which a grasp needs, not against a noisy
/// measurement of it. sigma(b) is sqrt(max(s_b^2, 0)), at least min_sigma.
///
/// A turn seen widens every longer horizon at once (issue 17). The window above hears of a change
/// of motion (the drift's reversal) at horizon b only b samples after it, when the forecasts made
/// before it come due; a grasp planned on sigma(7) in between closes on an old certainty. So each
/// bucket also keeps its last `surprise_window` scores' normalized squared error and excess,
///
///     z^2 = (1/3) sum over the axes of e_i^2 / (s_b,i^2 + r_i^2),   x_i = e_i^2 - s_b,i^2 - r_i^2
///
/// (s_b from before the score). The mean z^2 is 1 for a calibrated estimate; above
/// `surprise_threshold` c the bucket is surprised, and its excess eps_b = sqrt(max(mean x, 0))
/// per axis is a change of motion the forecasts did not know. A change of velocity dv shows at
/// horizon b' as an error dv b' T and at a longer horizon b as dv b T: (b / b') times as much,
/// while the model still forecasts the old motion. So the turn term
///
///     T_b = b max over surprised b' <= b of eps_b' / b'
///
/// is added in quadrature, sigma(b) = sqrt((w s_b)^2 + T_b^2) per axis (w the predictive
/// factor): a large h = 1 error, seen one sample after the turn, widens h = 1 .. H + max_gap at
/// once; as the turn reaches the longer horizons' own scores (b' = 2, 3, ... in turn) they carry
/// it on, until their windows hold it. A mean of `surprise_window` z^2 over c by chance (about 1
/// in 8 for 4 scores and c = 1.5) adds about b 0.7 s_b' (docs/prediction.md).
/// The estimates survive
/// reset() (they describe the predictor on this motion, not one track); the kept forecasts do not
/// (their grid is gone), and until `fresh_scores` forecasts of the new model have been scored at a
/// horizon, its sigma is at least the prior's (a restarted model is not yet as good as the old).
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
  int window = 60;             ///< the last scores the estimate averages (the prior the first)
  double min_sigma = 1e-4;     ///< m: no horizon is ever surer than this
  /// sigma() widened by predictive_factor(m): 2 sigma then bounds the next error as often as a
  /// normal's 2 sigma does, although s is estimated from m scores (Student's t). false: s itself.
  bool predictive = true;
  /// Scores a bucket's surprise averages (0: no turn term; at most 64).
  int surprise_window = 4;
  /// Mean z^2 above which a bucket is surprised (its excess then counts in the turn term).
  double surprise_threshold = 1.5;
  /// After reset() (a new model: the predictor restarted its axes), a horizon's sigma is at least
  /// the prior, prior_sigma * b per axis, until this many forecasts made since have been scored
  /// there: the estimates describe the old model, and a fresh one is not yet as good (0: never).
  int fresh_scores = 8;
};

class ForecastError {
 public:
  /// The longest window: 10^4 scores (45 minutes at 4 Hz) a horizon.
  static constexpr int kMaxWindow = 10'000;

  /// `horizon`: points per forecast (H >= 1); `max_gap`: fed-back samples a forecast may rest on
  /// (>= 0). Horizons 1 .. horizon + max_gap are estimated. Throws std::invalid_argument on a
  /// horizon below 1, a negative max_gap, a window outside 1..kMaxWindow or a prior or floor not
  /// positive and finite.
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
  /// Forgets the kept forecasts (a new track, a new grid); the estimates stay, but each horizon
  /// claims no more than the prior until `fresh_scores` new forecasts have been scored there.
  void reset();

  /// 1-sigma error per axis (m) of a point `samples` grid samples past the last measurement
  /// (1 .. horizon + max_gap; clamped into that range).
  Eigen::Vector3d sigma(int samples) const;
  /// T_b: the turn term sigma(samples) includes per axis (m; zero when nothing surprised).
  Eigen::Vector3d turn(int samples) const;
  /// Scores the estimate of that horizon has had (0 .. ; the prior not counted).
  int64_t scores(int samples) const;
  /// t_{m-1}(0.97725) sqrt(1 + 1/m) / 2, at most 2: how much wider than 2 s a 2-sigma interval
  /// for the next error must be when s is estimated from m scores (1.05 at m = 40; 2 for m < 2).
  static double predictive_factor(double m);
  int horizons() const { return static_cast<int>(sum_.size()); }

 private:
  struct Kept {
    int64_t utime = 0;
    int64_t period_us = 0;
    int occluded = 0;
    int points = 0;
    std::vector<Eigen::Vector3d> positions;  // capacity horizon, reserved once
  };
  size_t bucket(int samples) const;
  /// Adds e^2 and r^2 to bucket b's window, dropping its oldest entry when it is full.
  void add(size_t b, const Eigen::Vector3d& value, const Eigen::Vector3d& noise);
  /// One score's surprise: z^2 and the excess x per axis.
  struct Surprise {
    double z2 = 0;
    Eigen::Vector3d excess = Eigen::Vector3d::Zero();
  };
  /// Bucket b's s_b (sigma without the predictive factor or the turn) and its predictive factor,
  /// afresh from its window: kept, as they change only when an entry is added.
  void refresh(size_t b);
  /// Adds a score's surprise to bucket b's ring.
  void add_surprise(size_t b, Surprise s);
  /// T_b afresh for every bucket (after a sample's scores).
  void update_turn();

  int horizon_;
  ForecastErrorParams params_;
  std::vector<Eigen::Vector3d> window_;     // per bucket `window` squared errors e^2, a ring each
  std::vector<Eigen::Vector3d> noise_;      // the same rings: each score's sample variance r^2
  std::vector<Eigen::Vector3d> sum_;        // per bucket: the sum of its e^2 ring
  std::vector<Eigen::Vector3d> noise_sum_;  // per bucket: the sum of its r^2 ring
  std::vector<int> filled_;                 // per bucket: entries in its ring (the prior the first)
  std::vector<int> head_;                   // per bucket: where its next entry goes
  std::vector<int64_t> scores_;
  std::vector<Surprise> surprise_ring_;  // per bucket `surprise_window` scores, a ring each
  std::vector<Surprise> surprise_sum_;   // per bucket: the sum of its ring
  std::vector<int> surprise_filled_;     // per bucket: entries in its ring
  std::vector<Eigen::Vector3d> turn_;    // per bucket: T_b
  std::vector<Eigen::Vector3d> estimate_;  // per bucket: s_b (refresh())
  std::vector<double> widen_;              // per bucket: predictive_factor(filled_) or 1
  std::vector<int> fresh_;               // per bucket: scores since reset(), up to fresh_scores
  std::vector<Kept> kept_;               // a ring of the last `horizon` forecasts
  size_t next_ = 0;                      // where the next forecast goes
  size_t count_ = 0;                     // forecasts held
  bool scored_ = false;                  // last_scored_ is set
  int64_t last_scored_ = 0;
};

}  // namespace sg::predictor
