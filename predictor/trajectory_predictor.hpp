#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "predictor/axis_model.hpp"

namespace sg::predictor {

/// Which model predicts: the paper's Burg predictors, or a baseline behind the same interface.
enum class Model { kBurg, kKalman, kHold };
Model model_from_name(const std::string& name);  ///< "burg", "kalman", "hold"; throws otherwise
const char* model_name(Model model);

struct PredictorParams {
  Model model = Model::kBurg;
  int64_t period_us = 250'000;  ///< the predictor's sample period (4 Hz)
  int horizon = 16;             ///< H: samples forecast (16 = 4 s)
  int max_gap = 16;             ///< fed-back samples before the track is lost
  BurgParams burg;              ///< per axis; initial_coefficients below override it
  std::array<std::vector<double>, 3> initial_coefficients;  ///< offline-trained a_1..a_p per axis
  KalmanParams kalman;                                      ///< its period is set from period_us
  /// While tracking, a visible measurement farther than this from where the forecast puts the
  /// ball at its time is taken as not seen (a partly hidden ball's centroid, a mismatch): metres,
  /// 0 turns the gate off ...
  double gate = 0.010;
  /// ... unless measurements have disagreed for longer than this: then the ball is where they say.
  int64_t gate_patience_us = 500'000;
};

/// One measurement of the ball (OBJECT_POSITION).
struct Measurement {
  int64_t utime = 0;
  bool visible = false;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
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
  int occluded_samples = 0;                ///< fed-back samples at the end of the history
  TrackStatus status = TrackStatus::kNone;
};

/// Three axis predictors on a fixed sample period (section 5.5). Measurements at any rate are
/// brought onto the period by linear interpolation on their utime; when the ball is not seen, the
/// one-step forecast is fed back as the sample (up to max_gap samples, then the track is lost);
/// when it is seen again, the fed-back samples are replaced by the line between the last seen
/// position and the new one, so they do not corrupt the coefficients. Time comes only from the
/// measurements.
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
  /// rejected (counted, nothing changes) and returns nothing.
  std::vector<Forecast> add(const Measurement& m);

  uint64_t rejected() const { return rejected_; }
  /// Visible measurements the gate took as not seen.
  uint64_t gated() const { return gated_; }
  TrackStatus status() const { return status_; }
  const PredictorParams& params() const { return params_; }

 private:
  void reset();
  Forecast emit_sample(int64_t grid_utime, const Eigen::Vector3d& value, bool measured,
                       int64_t source);
  Eigen::Vector3d one_step() const;
  /// True when a visible measurement disagrees with the forecast beyond the gate (and patience).
  bool outside_gate(const Measurement& m);

  PredictorParams params_;
  std::array<std::unique_ptr<AxisModel>, 3> axes_;
  uint64_t rejected_ = 0;
  TrackStatus status_ = TrackStatus::kNone;
  bool started_ = false;
  int64_t last_utime_ = 0;  // last accepted measurement
  int64_t next_grid_ = 0;   // utime of the next grid sample to produce
  bool have_seen_ = false;
  int64_t seen_utime_ = 0;  // last visible measurement
  Eigen::Vector3d seen_position_ = Eigen::Vector3d::Zero();
  int64_t last_real_grid_ = 0;  // last grid sample made from measurements
  Eigen::Vector3d last_real_value_ = Eigen::Vector3d::Zero();
  int occluded_ = 0;                                       // consecutive fed-back samples
  Eigen::Vector3d last_sample_ = Eigen::Vector3d::Zero();  // the newest grid sample
  uint64_t gated_ = 0;
  std::optional<int64_t> gating_since_;  // first of the current run of gated measurements
};

}  // namespace sg::predictor
