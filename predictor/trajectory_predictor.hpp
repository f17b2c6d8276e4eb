#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "predictor/axis_model.hpp"
#include "predictor/forecast_error.hpp"

namespace sg::predictor {

/// The longest horizon H a predictor makes (and sg-grasp accepts in an OBJECT_TRAJECTORY).
constexpr int kMaxHorizon = 1000;

/// Which model predicts: the paper's Burg predictors, or a baseline behind the same interface.
enum class Model { kBurg, kKalman, kHold };
Model model_from_name(const std::string& name);  ///< "burg", "kalman", "hold"; throws otherwise
const char* model_name(Model model);

struct PredictorParams {
  Model model = Model::kBurg;
  int64_t period_us = 250'000;  ///< the predictor's sample period (4 Hz)
  int horizon = 16;             ///< H: samples forecast (16 = 4 s)
  int max_gap = 24;             ///< fed-back samples before the track is lost
  BurgParams burg;              ///< per axis; initial_coefficients below override it
  std::array<std::vector<double>, 3> initial_coefficients;  ///< offline-trained a_1..a_p per axis
  KalmanParams kalman;                                      ///< its period is set from period_us
  /// While tracking, a visible measurement farther than this from where the forecast puts the
  /// ball at its time is taken as not seen (a partly hidden ball's centroid, a mismatch): metres,
  /// 0 turns the gate off ...
  double gate = 0.010;
  /// ... unless measurements have disagreed for longer than this: then the ball is where they say.
  int64_t gate_patience_us = 500'000;
  /// The predictor's own sanity check, independent of any gate in front of it: a grid sample
  /// farther than this from the robot's base, or a forecast point that is not finite or farther
  /// than this from the newest sample, resets the predictor (m; the track is reported lost and
  /// starts again at the next sighting), so no input can leave it poisoned.
  double reset_distance = 10.0;
  /// The predictor's estimate of its own error per horizon (forecast_error.hpp).
  ForecastErrorParams error;
  /// Forecasts made on the first `after_gap` samples after an occlusion publish the sigma of a
  /// forecast still inside it, sigma(h + gap length): their history's newest samples are the line
  /// across the gap, not measurements, so the motion they continue is the gap's average, not the
  /// ball's now (a drift reversal hidden by the gap). By then the samples after the gap have
  /// been scored, and a turn among them widens the sigmas (ForecastError's turn term). They are
  /// still scored at h, as made from a measurement. 0: the sigma of h at once.
  int after_gap = 2;
};

/// One measurement of the ball (OBJECT_POSITION).
struct Measurement {
  int64_t utime = 0;
  bool visible = false;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  /// 1-sigma error per axis of position (point3_t.position_sigma, m); zero when unknown. The
  /// error estimate takes it out of each forecast's error against the measurement.
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
};

enum class TrackStatus { kNone, kTracking, kOccluded, kLost };

/// The forecast after the newest grid sample.
struct Forecast {
  int64_t utime = 0;         ///< time of the newest grid sample
  int64_t source_utime = 0;  ///< the measurement that produced it
  int64_t period_us = 0;
  Eigen::Vector3d sample =
      Eigen::Vector3d::Zero();             ///< the newest grid sample (fed back if occluded)
  std::vector<Eigen::Vector3d> positions;  ///< at utime + h * period_us, h = 1 .. horizon
  /// 1-sigma error per axis of each position (m): the predictor's own estimate from its past
  /// forecasts at h + occluded_samples samples past a measurement (ForecastError).
  std::vector<Eigen::Vector3d> sigma;
  int occluded_samples = 0;  ///< fed-back samples at the end of the history
  TrackStatus status = TrackStatus::kNone;
};

/// Three axis predictors on a fixed sample period (section 5.5). Measurements at any rate are
/// brought onto the period by linear interpolation on their utime; when the ball is not seen, the
/// one-step forecast is fed back as the sample (up to max_gap samples, then the track is lost);
/// when it is seen again, the fed-back samples are replaced by the line between the last seen
/// position and the new one, so they do not corrupt the coefficients. Time comes only from the
/// measurements. Each forecast carries the predictor's estimate of its error per point, learned
/// from its earlier forecasts against the measured samples (ForecastError).
///
///     TrajectoryPredictor predictor(params);
///     for (const Measurement& m : measurements) {
///       for (const Forecast& f : predictor.add(m)) publish(f);   // one per new grid sample
///     }
class TrajectoryPredictor {
 public:
  explicit TrajectoryPredictor(const PredictorParams& params);

  /// Adds a measurement; returns a forecast for each grid sample it completes (often none or one).
  /// A NaN or infinite visible position, a utime before the last one, or a repeated utime is
  /// rejected (counted, nothing changes) and returns nothing; after kMaxBackwardRun such times in
  /// a row (a clock stepped back, a log replayed again) the predictor resets and takes it. A
  /// forecast that fails the sanity check (reset_distance) resets the predictor: it is replaced
  /// by a kLost forecast and counted in resets().
  std::vector<Forecast> add(const Measurement& m);

  /// Measurements in a row whose time is not after the last before the predictor starts again.
  static constexpr int kMaxBackwardRun = 100;

  uint64_t rejected() const { return rejected_; }
  /// Times the predictor reset itself (a failed sanity check, a clock stepped back).
  uint64_t resets() const { return resets_; }
  /// Why it last reset ("" before any): "forecast (1e+298, 0, 0) m is 1e+298 m from ...".
  const std::string& last_reset() const { return last_reset_; }
  /// Visible measurements the gate took as not seen.
  uint64_t gated() const { return gated_; }
  /// Its estimate of its own error per horizon.
  const ForecastError& error() const { return error_; }
  TrackStatus status() const { return status_; }
  const PredictorParams& params() const { return params_; }

 private:
  void reset();
  /// reset(), counted, with the reason; returns the kLost forecast that replaces the bad one.
  Forecast recover(int64_t grid_utime, int64_t source, std::string why);
  /// "" when the forecast and its sample are sane (see reset_distance), else why not.
  std::string insane(const Forecast& f) const;
  Forecast emit_sample(int64_t grid_utime, const Eigen::Vector3d& value, bool measured,
                       int64_t source);
  /// The model's forecast one grid sample ahead of the newest: the newest forecast's first point.
  Eigen::Vector3d one_step() const;
  /// True when a visible measurement disagrees with the forecast beyond the gate (and patience).
  bool outside_gate(const Measurement& m);

  PredictorParams params_;
  std::unique_ptr<TrajectoryModel> model_;  // the three axes
  ForecastError error_;
  Eigen::Vector3d measured_sigma_ = Eigen::Vector3d::Zero();  // of the measurement being added
  uint64_t rejected_ = 0;
  TrackStatus status_ = TrackStatus::kNone;
  bool started_ = false;
  int64_t last_utime_ = 0;  // last accepted measurement
  int64_t next_grid_ = 0;   // utime of the next grid sample to produce
  bool have_seen_ = false;
  int64_t seen_utime_ = 0;  // last visible measurement
  int last_gap_ = 0;        // fed-back samples of the last occlusion ...
  int since_gap_ = 0;       // ... and measured samples since it ended
  Eigen::Vector3d seen_position_ = Eigen::Vector3d::Zero();
  int64_t last_real_grid_ = 0;  // last grid sample made from measurements
  Eigen::Vector3d last_real_value_ = Eigen::Vector3d::Zero();
  int occluded_ = 0;                                       // consecutive fed-back samples
  Eigen::Vector3d last_sample_ = Eigen::Vector3d::Zero();  // the newest grid sample
  uint64_t gated_ = 0;
  uint64_t resets_ = 0;
  std::string last_reset_;
  int backward_run_ = 0;                 // measurements in a row refused as not after the last
  std::optional<int64_t> gating_since_;  // first of the current run of gated measurements
  std::optional<Eigen::Vector3d> newest_one_step_;  // the newest forecast's first point
};

}  // namespace sg::predictor
