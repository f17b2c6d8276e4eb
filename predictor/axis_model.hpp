#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace sg::predictor {

/// One axis of the trajectory, sampled on the predictor's fixed period.
class AxisModel {
 public:
  virtual ~AxisModel() = default;
  /// Appends the newest sample: a measurement, or (measured = false) a prediction fed back
  /// through an occlusion, which must not teach the model anything.
  virtual void push(double value, bool measured) = 0;
  /// The value h = 1 .. horizon samples ahead of the newest.
  virtual std::vector<double> forecast(int horizon) const = 0;
  /// Replaces the newest `values.size()` samples (fed-back ones, once real measurements return).
  virtual void replace_newest(const std::vector<double>& values) = 0;
};

/// Burg's linear predictor (section 5.5): a sliding window of the last `window` samples with their
/// mean removed; the coefficients are re-estimated at every measured sample (online adaptation)
/// once the window holds order + 3 samples, or, when offline-trained coefficients are given, once
/// it holds `online_after` (a few seconds of an arc say little about a circle: Burg on them
/// forecasts worse than the offline coefficients); forecasts apply eq. 27 recursively, feeding
/// each prediction back.
struct BurgParams {
  int order = 12;
  int window = 480;
  bool remove_mean = true;
  std::vector<double> initial_coefficients;  ///< a_1 .. a_p trained offline (may be empty)
  int online_after = 240;  ///< samples before online estimates replace initial_coefficients
};
std::unique_ptr<AxisModel> make_burg_axis(const BurgParams& params);

/// A constant-velocity Kalman filter: state (position, velocity), white-acceleration process
/// noise of spectral density `q` (m^2/s^3), measurement noise `r` (m, standard deviation).
struct KalmanParams {
  double period = 0.25;
  double q = 1e-5;  ///< tuned on the paper's motion (docs/prediction.md)
  double r = 0.001;
};
std::unique_ptr<AxisModel> make_kalman_axis(const KalmanParams& params);

/// Holds the last value.
std::unique_ptr<AxisModel> make_hold_axis();

/// The three axes' models of a trajectory (x, y, z) as one: what TrajectoryPredictor feeds.
class TrajectoryModel {
 public:
  virtual ~TrajectoryModel() = default;
  /// AxisModel::push of each axis.
  virtual void push(const std::array<double, 3>& value, bool measured) = 0;
  /// AxisModel::forecast of each axis.
  virtual std::array<std::vector<double>, 3> forecast(int horizon) const = 0;
  /// AxisModel::replace_newest of each axis.
  virtual void replace_newest(const std::array<std::vector<double>, 3>& values) = 0;
};

/// Three Burg axes (params[i]: axis i's, their initial coefficients may differ) whose
/// coefficients are estimated together, in one pass over the three windows (burg3, issue 19):
/// the same forecasts as three make_burg_axis() bit for bit, in about the time of one.
std::unique_ptr<TrajectoryModel> make_burg_trajectory(const std::array<BurgParams, 3>& params);
/// Three axis models side by side (the Kalman and hold baselines).
std::unique_ptr<TrajectoryModel> make_axes_trajectory(
    std::array<std::unique_ptr<AxisModel>, 3> axes);

}  // namespace sg::predictor
