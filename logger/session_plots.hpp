#pragma once

/// The session report's four figures, drawn by gnuplot from PlotData (logger/plot.hpp). Each is
/// written as NAME.dat (the numbers, in blocks with a comment naming the series and columns),
/// NAME.gp (the gnuplot script) and NAME.png, side by side in the report directory, so a
/// researcher can edit a script and re-run it there: `gnuplot xy.gp`.
///
///  - xy (the paper's figure 5): the ball in the X-Y plane of the robot frame, metres, equal
///    aspect: the true path (green line), the measured positions (small blue crosses) and the
///    predicted path at h = data.predicted_horizon steps ahead (orange line); points whose time
///    lies in data.ball_held (the calibration, the carried ball) are left out.
///  - y_time (figure 6): Y against time: occlusions shaded light orange, truth as a green line,
///    measurements as blue crosses, predictions as orange circles, and grasp events as purple
///    dashed vertical markers with their names.
///  - latency: one histogram panel per stage of data.latency_ms (in map order), titled with the
///    stage, its sample count and median; x is logarithmic when the bins are log-spaced (see
///    histogram_edges()).
///  - arm: three panels (X, Y, Z against time, one time axis): the arm's Cartesian targets as
///    orange crosses and the tool's actual position as a blue line, with the grasp events as in
///    y_time (named on the top panel).
///
/// A figure (or a latency panel) without data shows the note "no data", so links in a report
/// never break. Event names are set in up to three rows so they do not overlap; a marker with no
/// free row is drawn without its name (report.md lists every event).
///
///     PlotData data;                                     // filled while reading the log
///     for (const std::string& png : write_session_plots(data, "session-report"))
///       std::cout << png << "\n";  // session-report/xy.png, .../y_time.png, ...
///
/// Lines break where consecutive points are more than five median sample intervals apart (a
/// gap in the log, a lost track) rather than join across the gap.

#include <string>
#include <vector>

#include "logger/plot.hpp"
#include "logger/plot_data.hpp"

namespace sg::logger {

/// Writes dir/NAME.dat and dir/NAME.gp for NAME = xy, y_time, latency, arm (creating dir if
/// needed), runs `gnuplot` (a name looked up on PATH, or a path) on each script, and returns the
/// PNGs' paths in that order. Throws GnuplotMissing when there is no gnuplot (the .dat and .gp
/// files are written first, so the figures can be drawn later), PlotError naming the file when
/// a file cannot be written or gnuplot fails.
std::vector<std::string> write_session_plots(const PlotData& data, const std::string& dir,
                                             const std::string& gnuplot = "gnuplot");

/// The bin edges (counts.size() + 1 of them) of a Histogram, which stores only lo, hi and the
/// counts. Rule: the bins are log-spaced (edge i = lo * (hi / lo)^(i / n)) when lo > 0 and
/// hi / lo > 100, and evenly spaced over [lo, hi] otherwise. Empty for no counts.
std::vector<double> histogram_edges(const Histogram& histogram);

/// True when histogram_edges() takes the bins as log-spaced (lo > 0 and hi / lo > 100).
bool histogram_is_log(const Histogram& histogram);

/// Rows (0, 1 or 2 down from the top of the axes) for the names of markers at `xs`, so that no
/// two names in a row overlap; -1 for a marker that gets no name. A name of `chars[i]`
/// characters is `char_px` pixels a character wide and starts just right of its marker (just
/// left of it, ending there, when it would pass the right edge); the axes span [lo, hi] over
/// `axes_px` pixels.
std::vector<int> label_rows(const std::vector<double>& xs, const std::vector<size_t>& chars,
                            double lo, double hi, double axes_px, double char_px = 7);

}  // namespace sg::logger
