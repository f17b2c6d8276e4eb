#pragma once

#include <array>
#include <string>
#include <vector>

#include "predictor/trajectory_predictor.hpp"

namespace sg::predictor {

/// Visible measurements from a CSV of `t,x,y,z` lines: t in microseconds since the epoch (above
/// 1e12) or in seconds; a header and `#` comments are skipped. A malformed line throws
/// `FILE:LINE: expected t,x,y,z`.
std::vector<Measurement> read_training_csv(const std::string& path);

/// Visible point3_t positions on `channel` of an LCM log (OBJECT_POSITION or GROUND_TRUTH);
/// events that do not decode exactly as point3_t are skipped.
std::vector<Measurement> read_training_log(const std::string& path, const std::string& channel);

/// Burg coefficients trained offline per axis (section 5.5, eq. 27-31).
struct TrainedCoefficients {
  int order = 0;
  double period = 0;                                ///< s
  int samples = 0;                                  ///< on the period grid, per axis
  std::array<std::vector<double>, 3> coefficients;  ///< a_1..a_p per axis
  std::array<std::vector<double>, 3> error_power;   ///< E_0..E_p per axis
};

/// Resamples `measurements` onto the period of `params` (as the live predictor does), removes
/// each axis's mean and runs Burg of order `params.burg.order` on it. Throws when there are
/// fewer than 2p + 3 samples.
TrainedCoefficients train_coefficients(const std::vector<Measurement>& measurements,
                                       const PredictorParams& params);

/// Writes `trained` as YAML that read_coefficients() reads (to a temporary file, then renamed);
/// `source` is recorded in it.
void write_coefficients(const std::string& path, const TrainedCoefficients& trained,
                        const std::string& source);

}  // namespace sg::predictor
