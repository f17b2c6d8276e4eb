#include "logger/session_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <system_error>

namespace sg::logger {
namespace {

using Rows = std::vector<std::vector<double>>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr size_t kMaxEventLabel = 28;
constexpr int kLabelRows = 3;

// The median time step of a series' points, or NaN for fewer than three points.
double median_step(const std::vector<TimedPoint>& points) {
  if (points.size() <= 2) return kNaN;
  std::vector<double> steps;
  steps.reserve(points.size() - 1);
  for (size_t i = 1; i < points.size(); ++i) steps.push_back(points[i].t - points[i - 1].t);
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  return steps[steps.size() / 2];
}

// Rows of the chosen columns of a series (-1 is the time, 0..2 the position's axes); with
// `break_gaps` a NaN row (a break in a line) where the time step exceeds five median steps.
Rows rows_of(const DecimatedSeries& series, const std::vector<int>& columns, bool break_gaps) {
  const std::vector<TimedPoint>& points = series.points();
  const double median = break_gaps ? median_step(points) : kNaN;
  const double gap = median > 0 ? 5 * median : std::numeric_limits<double>::infinity();
  Rows rows;
  rows.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (i > 0 && points[i].t - points[i - 1].t > gap) rows.push_back({kNaN});
    std::vector<double> row;
    for (int c : columns) row.push_back(c < 0 ? points[i].t : points[i].p[c]);
    rows.push_back(std::move(row));
  }
  return rows;
}

// A span of values seen so far (empty until the first finite one).
struct Span {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  void add(double v) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  void add(const DecimatedSeries& s) {
    for (const TimedPoint& p : s.points()) add(p.t);
  }
  bool empty() const { return lo > hi; }
};

// The time axis of y_time and arm: every series, occlusion and event, padded by 2 %.
Span time_span(const PlotData& data, const std::vector<const DecimatedSeries*>& series) {
  Span s;
  for (const DecimatedSeries* one : series) s.add(*one);
  for (const auto& [start, end] : data.occlusions) s.add(start), s.add(end);
  for (const auto& event : data.events) s.add(event.first);
  if (s.empty()) return Span{0, 1};
  const double pad = s.hi > s.lo ? 0.02 * (s.hi - s.lo) : 0.5;
  return Span{s.lo - pad, s.hi + pad};
}

std::string colour(const Rgb& rgb) { return "rgb '" + rgb.hex() + "'"; }

// One clause of a plot command: block `index` of `file`, `using`, a style and a legend title.
std::string series(const std::string& file, int index, const std::string& using_columns,
                   const std::string& style, const Rgb& rgb, const std::string& title) {
  return gnuplot_string(file) + " index " + std::to_string(index) + " using " + using_columns +
         " with " + style + " lc " + colour(rgb) +
         (title.empty() ? " notitle" : " title " + gnuplot_string(title));
}

// "plot A, B, ..." or, with nothing to plot, fixed ranges and a "no data" note.
std::string plot_command(const std::vector<std::string>& clauses, bool fixed_x = false) {
  if (clauses.empty()) {
    return std::string(fixed_x ? "" : "set xrange [0:1]\n") +
           "set yrange [0:1]\n"
           "set label 1 'no data' at graph 0.5, graph 0.5 center front tc " +
           colour(palette::kNote) + " font ',18'\nplot NaN notitle\nunset label 1\n";
  }
  std::string out = "plot ";
  for (size_t i = 0; i < clauses.size(); ++i) out += (i ? ", \\\n     " : "") + clauses[i];
  return out + "\n";
}

// The start of every script: how to re-run it, the terminal, and the common style.
std::string preamble(const std::string& name, int width, int height) {
  return "# " + name + ".png from " + name +
         ".dat, written by sg-report (docs/logs.md); edit and re-run here with: gnuplot " + name +
         ".gp\nset terminal pngcairo size " + std::to_string(width) + "," + std::to_string(height) +
         " noenhanced font 'Sans,10'\nset output '" + name + ".png'\nset border lc " +
         colour(palette::kBorder) + "\nset grid back lt 1 lw 1 lc " + colour(palette::kGrid) +
         "\nset tics out nomirror\nset key box lc " + colour(palette::kGrid) +
         " opaque\nset style fill solid 1.0 noborder\n";
}

// Where a figure's axes sit, in pixels from its left and top edges (so stacked panels align and
// names can be placed knowing the axes' width).
struct Box {
  int width, height;             // the figure
  int left, right, top, bottom;  // the axes: x from left to right, y from top to bottom
};

std::string axes_at(const Box& b) {
  char text[192];
  std::snprintf(text, sizeof text,
                "set lmargin at screen %.5f\nset rmargin at screen %.5f\n"
                "set tmargin at screen %.5f\nset bmargin at screen %.5f\n",
                static_cast<double>(b.left) / b.width, static_cast<double>(b.right) / b.width,
                1.0 - static_cast<double>(b.top) / b.height,
                1.0 - static_cast<double>(b.bottom) / b.height);
  return text;
}

// The legend as one centred row whose top is `y_px` pixels below the figure's top.
std::string key_row(const Box& b, int y_px) {
  char text[128];
  std::snprintf(text, sizeof text,
                "set key at screen 0.5, screen %.5f center top horizontal nobox samplen 3\n",
                1.0 - static_cast<double>(y_px) / b.height);
  return text;
}

// The figure's title, centred, `y_px` pixels below its top (gnuplot's own title would sit on the
// legend's row, just above the axes).
std::string title_row(const Box& b, const std::string& title, int y_px = 20) {
  char at[64];
  std::snprintf(at, sizeof at, " at screen 0.5, screen %.5f center",
                1.0 - static_cast<double>(y_px) / b.height);
  return "set label 99 " + gnuplot_string(title) + at + " font ',13'\n";
}

std::string range(const char* axis, double lo, double hi) {
  return std::string("set ") + axis + "range [" + gnuplot_number(lo) + ":" + gnuplot_number(hi) +
         "]\n";
}

std::string event_text(const std::string& text) {
  if (text.size() <= kMaxEventLabel) return text;
  return text.substr(0, kMaxEventLabel - 3) + "...";
}

// Dashed purple markers for the grasp events, named (in rows that do not overlap) when `names`.
std::string event_markers(const PlotData& data, const Span& x, const Box& box, bool names) {
  std::vector<double> xs;
  std::vector<size_t> chars;
  for (const auto& [t, text] : data.events) {
    xs.push_back(t);
    chars.push_back(event_text(text).size());
  }
  const double axes_px = box.right - box.left;
  const std::vector<int> rows = label_rows(xs, chars, x.lo, x.hi, axes_px);
  std::string out = data.events.empty() ? "" : "# grasp events (time in s)\n";
  for (size_t i = 0; i < data.events.size(); ++i) {
    const std::string t = gnuplot_number(xs[i]);
    out += "set arrow from " + t + ", graph 0 to " + t + ", graph 1 nohead back dt 2 lw 1 lc " +
           colour(palette::kPurple) + "\n";
    if (!names || rows[i] < 0) continue;
    const bool left = (xs[i] - x.lo) / (x.hi - x.lo) + (chars[i] + 1) * 7 / axes_px > 1;
    char offset[64];
    std::snprintf(offset, sizeof offset, " offset character %.1f, %.1f", left ? -0.4 : 0.4,
                  -1.0 - 1.2 * rows[i]);
    out += "set label " + gnuplot_string(event_text(data.events[i].second)) + " at " + t +
           ", graph 1" + (left ? " right" : " left") + offset + " front tc " +
           colour(palette::kPurple) + "\n";
  }
  return out;
}

std::string figure_files(const std::string& dir, const std::string& name, const GnuplotData& dat,
                         const std::string& script) {
  dat.save((std::filesystem::path(dir) / (name + ".dat")).string());
  write_text_file((std::filesystem::path(dir) / (name + ".gp")).string(), script);
  return name;
}

std::string horizon_title(const PlotData& data) {
  return "predicted (h = " + std::to_string(data.predicted_horizon) + ")";
}

// Equal spans for X and Y about the data's centre, so one metre is as long across as up on a
// square axes box; [0, 1] for no data.
std::pair<Span, Span> plane_ranges(const std::vector<const DecimatedSeries*>& series) {
  Span x, y;
  for (const DecimatedSeries* one : series) {
    for (const TimedPoint& p : one->points()) x.add(p.p.x()), y.add(p.p.y());
  }
  if (x.empty() || y.empty()) return {Span{0, 1}, Span{0, 1}};
  const double half = std::max({x.hi - x.lo, y.hi - y.lo, 0.01}) * 0.55;
  const double cx = (x.lo + x.hi) / 2, cy = (y.lo + y.hi) / 2;
  return {Span{cx - half, cx + half}, Span{cy - half, cy + half}};
}

// The points of a series outside the spans (sorted, apart), so figure 5 leaves out the ball that
// the arm holds.
DecimatedSeries outside(const DecimatedSeries& series,
                        const std::vector<std::pair<double, double>>& spans) {
  DecimatedSeries kept(series.points().size() + 2);  // room for all: nothing thinned again
  for (const TimedPoint& p : series.points()) {
    auto after = std::upper_bound(spans.begin(), spans.end(), p.t,
                                  [](double t, const auto& span) { return t < span.first; });
    const bool inside = after != spans.begin() && p.t < std::prev(after)->second;
    if (!inside) kept.add(p.t, p.p);
  }
  return kept;
}

// A comment in xy.gp naming the spans left out.
std::string held_note(const PlotData& data) {
  if (data.ball_held.empty()) return "";
  std::string out = "# left out: the points while the arm holds the ball (start, end in s):";
  for (const auto& [start, end] : data.ball_held) {
    out += ' ';
    out += gnuplot_number(start);
    out += '-';
    out += gnuplot_number(end);
  }
  out += '\n';
  return out;
}

std::string xy_figure(const PlotData& data, const std::string& dir) {
  const Box box{800, 800, 90, 760, 70, 740};  // a square axes box
  const DecimatedSeries true_path = outside(data.truth, data.ball_held);
  const DecimatedSeries measured_path = outside(data.measured, data.ball_held);
  const DecimatedSeries predicted_path = outside(data.predicted, data.ball_held);
  GnuplotData dat;
  const int truth =
      dat.add_block("true (GROUND_TRUTH): X (m), Y (m)", rows_of(true_path, {0, 1}, true));
  const int measured = dat.add_block("measured (OBJECT_POSITION): X (m), Y (m)",
                                     rows_of(measured_path, {0, 1}, false));
  const int predicted = dat.add_block(horizon_title(data) + " (OBJECT_TRAJECTORY): X (m), Y (m)",
                                      rows_of(predicted_path, {0, 1}, true));
  std::vector<std::string> clauses;
  const std::string file = "xy.dat";
  if (truth >= 0)
    clauses.push_back(series(file, truth, "1:2", "lines lw 2", palette::kGreen, "true"));
  if (measured >= 0) {
    clauses.push_back(
        series(file, measured, "1:2", "points pt 2 ps 0.9", palette::kBlue, "measured"));
  }
  if (predicted >= 0) {
    clauses.push_back(
        series(file, predicted, "1:2", "lines lw 1", palette::kOrange, horizon_title(data)));
  }
  const auto [x, y] = plane_ranges({&true_path, &measured_path, &predicted_path});
  const std::string script = preamble("xy", box.width, box.height) + held_note(data) +
                             axes_at(box) + key_row(box, 38) +
                             title_row(box, "Ball in the X-Y plane (paper figure 5)") +
                             "set xlabel 'X (m)'\nset ylabel 'Y (m)'\n" + range("x", x.lo, x.hi) +
                             range("y", y.lo, y.hi) + plot_command(clauses, true);
  return figure_files(dir, "xy", dat, script);
}

std::string occlusion_bands(const PlotData& data) {
  std::string out = data.occlusions.empty() ? "" : "# occlusions (start, end in s)\n";
  for (const auto& [start, end] : data.occlusions) {
    out += "set object rect from " + gnuplot_number(start) + ", graph 0 to " + gnuplot_number(end) +
           ", graph 1 behind fc " + colour(palette::kShade) + " fs solid 1.0 noborder\n";
  }
  return out;
}

std::string y_time_figure(const PlotData& data, const std::string& dir) {
  const Box box{1100, 500, 80, 1075, 70, 440};
  GnuplotData dat;
  const int truth =
      dat.add_block("true (GROUND_TRUTH): t (s), Y (m)", rows_of(data.truth, {-1, 1}, true));
  const int predicted = dat.add_block(horizon_title(data) + " (OBJECT_TRAJECTORY): t (s), Y (m)",
                                      rows_of(data.predicted, {-1, 1}, false));
  const int measured = dat.add_block("measured (OBJECT_POSITION): t (s), Y (m)",
                                     rows_of(data.measured, {-1, 1}, false));
  const Span x = time_span(data, {&data.truth, &data.predicted, &data.measured});
  std::vector<std::string> clauses;
  const std::string file = "y_time.dat";
  if (!data.occlusions.empty()) {
    clauses.push_back("keyentry with boxes fc " + colour(palette::kShade) + " title 'occluded'");
  }
  if (truth >= 0)
    clauses.push_back(series(file, truth, "1:2", "lines lw 1.5", palette::kGreen, "true"));
  if (predicted >= 0) {
    clauses.push_back(series(file, predicted, "1:2", "points pt 6 ps 1.0", palette::kOrange,
                             horizon_title(data)));
  }
  if (measured >= 0) {
    clauses.push_back(
        series(file, measured, "1:2", "points pt 2 ps 0.9", palette::kBlue, "measured"));
  }
  if (truth < 0 && predicted < 0 && measured < 0) clauses.clear();
  const std::string script =
      preamble("y_time", box.width, box.height) + axes_at(box) + key_row(box, 38) +
      title_row(box, "Y against time with occlusions (paper figure 6)") +
      "set xlabel 'time (s)'\nset ylabel 'Y (m)'\n" + range("x", x.lo, x.hi) +
      occlusion_bands(data) + event_markers(data, x, box, true) + plot_command(clauses, true);
  return figure_files(dir, "y_time", dat, script);
}

// The value below which half the counts lie, read from the bins (at a bin's centre).
double histogram_median(const std::vector<double>& edges, const std::vector<int64_t>& counts,
                        bool log) {
  int64_t total = 0;
  for (int64_t c : counts) total += std::max<int64_t>(0, c);
  int64_t seen = 0;
  for (size_t i = 0; i < counts.size(); ++i) {
    seen += std::max<int64_t>(0, counts[i]);
    if (2 * seen >= total) {
      return log ? std::sqrt(edges[i] * edges[i + 1]) : (edges[i] + edges[i + 1]) / 2;
    }
  }
  return kNaN;
}

// A step of 1, 2 or 5 times a power of ten giving at most about four ticks up to `top`.
double count_step(double top) {
  const double raw = std::max(1.0, top / 4);
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0}) {
    if (m * decade >= raw) return m * decade;
  }
  return 10 * decade;
}

// One latency panel: the stage's bins (those with counts) as bars from edge to edge.
std::string latency_panel(const std::string& stage, const Histogram& histogram, GnuplotData& dat) {
  const std::vector<double> edges = histogram_edges(histogram);
  const bool log = !edges.empty() && histogram_is_log(histogram);
  int64_t total = 0, top = 0;
  Rows bins;
  for (size_t i = 0; i < histogram.counts.size(); ++i) {
    const int64_t c = std::max<int64_t>(0, histogram.counts[i]);
    total += c;
    top = std::max(top, c);
    if (c > 0) bins.push_back({edges[i], edges[i + 1], static_cast<double>(c)});
  }
  std::string title = stage + ": n = " + std::to_string(total);
  if (total > 0) {
    char median[64];
    std::snprintf(median, sizeof median, ", median ~ %.3g ms",
                  histogram_median(edges, histogram.counts, log));
    title += median;
  }
  const int block = dat.add_block(stage + ": bin from (ms), bin to (ms), count", bins);
  std::string out = "set title " + gnuplot_string(title) + "\n" +
                    (log ? "set logscale x 10\n" : "unset logscale x\n");
  const bool span = !edges.empty() && edges.back() > edges.front();
  out += span ? range("x", edges.front(), edges.back()) : range("x", 0, 1);
  if (block < 0) return out + "set ytics autofreq\n" + plot_command({}, true);
  return out + "set yrange [0:*]\nset ytics 0, " + gnuplot_number(count_step(top)) +
         "\nplot 'latency.dat' index " + std::to_string(block) +
         " using (($1+$2)/2):($3/2):1:2:(0):3 with boxxyerror fs solid 1.0 border lc " +
         colour(palette::kDarkBlue) + " fc " + colour(palette::kBlue) + " notitle\n";
}

std::string latency_figure(const PlotData& data, const std::string& dir) {
  constexpr int kWidth = 900, kPanel = 230;  // pixels: 40 of title, 140 of axes, 50 of labels
  const int panels = std::max<int>(1, static_cast<int>(data.latency_ms.size()));
  const int height = panels * kPanel + (data.latency_ms.empty() ? 70 : 0);
  GnuplotData dat;
  std::string script = preamble("latency", kWidth, height) +
                       "set multiplot\nset key off\n"
                       "set xlabel 'latency (ms)'\nset ylabel 'count'\nset format x '%g'\n";
  int k = 0;
  for (const auto& [stage, histogram] : data.latency_ms) {
    script += axes_at(Box{kWidth, height, 80, 875, k * kPanel + 40, k * kPanel + 180}) +
              latency_panel(stage, histogram, dat);
    ++k;
  }
  if (data.latency_ms.empty()) {
    script += axes_at(Box{kWidth, height, 80, 875, 40, height - 50}) +
              "set title 'Latency per stage'\n" + plot_command({});
  }
  return figure_files(dir, "latency", dat, script + "unset multiplot\n");
}

// One of the arm figure's panels: coordinate `axis` (0, 1, 2 for X, Y, Z) against time.
std::string arm_panel(const PlotData& data, int axis, int actual, int target, const Span& x,
                      const Box& box) {
  static const char* const kAxes[] = {"X", "Y", "Z"};
  const std::string using_columns = "1:" + std::to_string(axis + 2);
  std::vector<std::string> clauses;
  if (actual >= 0) {
    clauses.push_back(
        series("arm.dat", actual, using_columns, "lines lw 2", palette::kBlue, "tool (actual)"));
  }
  if (target >= 0) {
    clauses.push_back(
        series("arm.dat", target, using_columns, "points pt 2 ps 0.9", palette::kOrange, "target"));
  }
  return "unset arrow\nunset label\n" + axes_at(box) + "set ylabel '" + kAxes[axis] + " (m)'\n" +
         (axis == 0 ? key_row(box, 38) : "set key off\n") +
         (axis == 2 ? "set xlabel 'time (s)'\n" : "") + event_markers(data, x, box, axis == 0) +
         plot_command(clauses, true);
}

std::string arm_figure(const PlotData& data, const std::string& dir) {
  constexpr int kWidth = 1100, kHeight = 820, kTop = 70, kPanel = 232, kGap = 22;
  GnuplotData dat;
  const int actual = dat.add_block("tool (ARM_STATUS): t (s), X (m), Y (m), Z (m)",
                                   rows_of(data.arm_actual, {-1, 0, 1, 2}, true));
  const int target = dat.add_block("target (ARM_COMMAND): t (s), X (m), Y (m), Z (m)",
                                   rows_of(data.arm_target, {-1, 0, 1, 2}, false));
  const Span x = time_span(data, {&data.arm_actual, &data.arm_target});
  std::string script = preamble("arm", kWidth, kHeight) +
                       "set multiplot title 'Arm: targets and tool position' font ',13'\n" +
                       range("x", x.lo, x.hi) + "set format x ''\n";
  for (int axis = 0; axis < 3; ++axis) {
    const int top = kTop + axis * kPanel;
    if (axis == 2) script += "set format x '%g'\n";
    script += arm_panel(data, axis, actual, target, x,
                        Box{kWidth, kHeight, 80, 1075, top, top + kPanel - kGap});
  }
  return figure_files(dir, "arm", dat, script + "unset multiplot\n");
}

}  // namespace

bool histogram_is_log(const Histogram& histogram) {
  return histogram.lo > 0 && std::isfinite(histogram.hi) && histogram.hi / histogram.lo > 100;
}

std::vector<double> histogram_edges(const Histogram& histogram) {
  const size_t n = histogram.counts.size();
  std::vector<double> edges;
  if (n == 0) return edges;
  edges.reserve(n + 1);
  const bool log = histogram_is_log(histogram);
  for (size_t i = 0; i <= n; ++i) {
    const double f = static_cast<double>(i) / static_cast<double>(n);
    edges.push_back(log ? histogram.lo * std::pow(histogram.hi / histogram.lo, f)
                        : histogram.lo + (histogram.hi - histogram.lo) * f);
  }
  edges.back() = histogram.hi;
  return edges;
}

std::vector<int> label_rows(const std::vector<double>& xs, const std::vector<size_t>& chars,
                            double lo, double hi, double axes_px, double char_px) {
  std::vector<int> rows(xs.size(), -1);
  if (!(hi > lo) || !(axes_px > 0)) return rows;
  std::vector<double> row_end(kLabelRows, -std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < xs.size() && i < chars.size(); ++i) {
    if (!std::isfinite(xs[i])) continue;
    const double at = (xs[i] - lo) / (hi - lo) * axes_px;
    const double width = (static_cast<double>(chars[i]) + 1) * char_px;
    const double start = at + width > axes_px ? at - width : at;  // right-aligned at the edge
    for (int r = 0; r < kLabelRows; ++r) {
      if (start <= row_end[r]) continue;
      rows[i] = r;
      row_end[r] = start + width;
      break;
    }
  }
  return rows;
}

std::vector<std::string> write_session_plots(const PlotData& data, const std::string& dir,
                                             const std::string& gnuplot) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw PlotError("cannot create directory '" + dir + "': " + error.message());
  const std::vector<std::string> names = {xy_figure(data, dir), y_time_figure(data, dir),
                                          latency_figure(data, dir), arm_figure(data, dir)};
  std::string program;
  try {
    program = find_gnuplot(gnuplot);
  } catch (const GnuplotMissing& e) {
    throw GnuplotMissing(std::string(e.what()) + "; the scripts are written, to run later: " + dir +
                         "/*.gp");
  }
  std::vector<std::string> pngs;
  for (const std::string& name : names) {
    run_gnuplot(program, dir, name + ".gp");
    pngs.push_back((std::filesystem::path(dir) / (name + ".png")).string());
  }
  return pngs;
}

}  // namespace sg::logger
