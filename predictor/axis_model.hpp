#pragma once

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

}  // namespace sg::predictor
