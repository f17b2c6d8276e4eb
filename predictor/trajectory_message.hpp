#pragma once

/// The predictor's values as LCM messages and back: the one place sg-predictor and the
/// in-process trials (system/grasp_trial.hpp) convert, so a forecast reaches sg-grasp alike.
///
///     TrajectoryPredictor predictor(params);
///     for (const Forecast& f : predictor.add(measurement_of(object_position)))
///       bus.publish("OBJECT_TRAJECTORY", to_trajectory_t(f, params));

#include "predictor/trajectory_predictor.hpp"
#include "stereograsp/point3_t.hpp"
#include "stereograsp/trajectory_t.hpp"

namespace sg::predictor {

/// An OBJECT_POSITION as a measurement: visible when the message says so; the position as sent
/// (the predictor itself rejects non-finite values and time going backwards).
Measurement measurement_of(const stereograsp::point3_t& position);

/// A forecast as OBJECT_TRAJECTORY (eq. 27-34): H points, point 0 one period after the newest
/// grid sample (`start_utime = utime + period_us`), the track status, and the model that made it.
stereograsp::trajectory_t to_trajectory_t(const Forecast& forecast, const PredictorParams& params);

}  // namespace sg::predictor
