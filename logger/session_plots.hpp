#pragma once

/// The session report's four figures, drawn from PlotData with Plot (logger/plot.hpp):
///
///  - xy.png (the paper's figure 5): the ball in the X-Y plane of the robot frame, metres, equal
///    aspect: the true path (green line), the measured positions (small blue crosses) and the
///    predicted path at h = data.predicted_horizon steps ahead (orange line).
///  - y_time.png (figure 6): Y against time: occlusions shaded light orange, truth as a green
///    line, measurements as blue crosses, predictions as orange circles, and grasp events as
///    labelled purple dashed vertical markers.
///  - latency.png: one histogram panel per stage of data.latency_ms (in map order), titled with
///    the stage, its sample count and median; x is logarithmic when the bins are log-spaced
///    (see histogram_edges()).
///  - arm.png: three panels (X, Y, Z against time): the arm's Cartesian targets as orange
///    crosses and the tool's actual position as a blue line, with the grasp events as in
///    y_time.png (labelled on the top panel).
///
/// Every figure is always written: a figure (or a latency panel) without data shows the note
/// "no data", so links in a report never break.
///
///     PlotData data;                    // filled while reading the log
///     for (const std::string& png : write_session_plots(data, "session-report"))
///       std::cout << png << "\n";       // session-report/xy.png, .../y_time.png, ...
///
/// Lines break where consecutive points are more than five median sample intervals apart (a
/// gap in the log, a lost track) rather than join across the gap.

#include <string>
#include <vector>

#include "logger/plot_data.hpp"

namespace sg::logger {

/// Writes dir/xy.png, dir/y_time.png, dir/latency.png and dir/arm.png (creating dir if needed)
/// and returns their paths in that order. Throws std::runtime_error naming the path when a file
/// cannot be written.
std::vector<std::string> write_session_plots(const PlotData& data, const std::string& dir);

/// The bin edges (counts.size() + 1 of them) of a Histogram, which stores only lo, hi and the
/// counts. Rule: the bins are log-spaced (edge i = lo * (hi / lo)^(i / n)) when lo > 0 and
/// hi / lo > 100, and evenly spaced over [lo, hi] otherwise. Empty for no counts.
std::vector<double> histogram_edges(const Histogram& histogram);

/// True when histogram_edges() takes the bins as log-spaced (lo > 0 and hi / lo > 100).
bool histogram_is_log(const Histogram& histogram);

}  // namespace sg::logger
