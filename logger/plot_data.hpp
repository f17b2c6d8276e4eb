#pragma once

/// What a session report's figures show, gathered in one streaming pass over a log with memory
/// that does not grow with the log: each series keeps at most `capacity` points, and when it is
/// full it drops every other point and keeps only every second one from then on (so a one-hour
/// log and a one-minute log cost the same).
///
///     DecimatedSeries measured(4000);
///     measured.add(t_seconds, position);          // for every OBJECT_POSITION
///     for (const TimedPoint& p : measured.points()) draw(p);

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace sg::logger {

/// A position at a time: seconds since the session's first event, metres in the robot frame.
struct TimedPoint {
  double t = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

/// A time series that keeps at most `capacity` points, evenly thinned.
class DecimatedSeries {
 public:
  DecimatedSeries() : DecimatedSeries(4000) {}
  explicit DecimatedSeries(size_t capacity) : capacity_(capacity < 2 ? 2 : capacity) {}

  void add(double t, const Eigen::Vector3d& p) {
    if (seen_++ % stride_ != 0) return;
    points_.push_back({t, p});
    if (points_.size() < capacity_) return;
    size_t kept = 0;  // keep every other point, and from now on every other one of what comes
    for (size_t i = 0; i < points_.size(); i += 2) points_[kept++] = points_[i];
    points_.resize(kept);
    stride_ *= 2;
  }

  const std::vector<TimedPoint>& points() const { return points_; }
  /// Points offered, kept or not.
  int64_t seen() const { return seen_; }

 private:
  size_t capacity_;
  int64_t stride_ = 1;
  int64_t seen_ = 0;
  std::vector<TimedPoint> points_;
};

/// Counts in fixed bins over [lo, hi); values outside land in the first or last bin.
/// The bins are log-spaced when lo > 0 and hi / lo > 100 (bin i spans lo * (hi / lo)^(i / n) to
/// lo * (hi / lo)^((i + 1) / n)), and evenly spaced otherwise: latency.png draws them so
/// (histogram_edges() in logger/session_plots.hpp).
struct Histogram {
  double lo = 0, hi = 1;
  std::vector<int64_t> counts;
};

/// Everything the figures need (docs/logs.md):
///  - xy.png, the paper's figure 5: the X-Y plane with measured, predicted and true paths, but
///    none of their points while the arm holds the ball (`ball_held`);
///  - y_time.png, figure 6: Y against time, crosses for measurements, circles for predictions,
///    occlusions shaded;
///  - latency.png: a histogram per stage;
///  - arm.png: the arm's targets and actual tool positions over time.
struct PlotData {
  DecimatedSeries measured;   ///< OBJECT_POSITION, visible ones
  DecimatedSeries predicted;  ///< OBJECT_TRAJECTORY's point at predicted_horizon, at its time
  DecimatedSeries truth;      ///< GROUND_TRUTH
  int predicted_horizon = 4;  ///< which step of each trajectory `predicted` holds
  std::vector<std::pair<double, double>> occlusions;  ///< [start, end), seconds
  /// [start, end), seconds: while the arm holds the ball (the calibration, the carried ball:
  /// logger/session_phase.hpp); xy.png leaves the points in them out.
  std::vector<std::pair<double, double>> ball_held;
  std::map<std::string, Histogram> latency_ms;  ///< per stage, milliseconds
  DecimatedSeries arm_target;  ///< ARM_COMMAND Cartesian targets, at the command's time
  DecimatedSeries arm_actual;  ///< ARM_STATUS tool positions
  std::vector<std::pair<double, std::string>> events;  ///< grasp states and outcomes, at time
};

}  // namespace sg::logger
