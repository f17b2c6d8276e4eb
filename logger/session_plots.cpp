#include "logger/session_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <system_error>

#include "logger/plot.hpp"

namespace sg::logger {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kNoData = "no data";
constexpr size_t kMaxEventLabel = 28;

// Times and one coordinate of a series; with `break_gaps`, a NaN is inserted where the time step
// exceeds five median steps, so a line does not join across a gap.
struct Columns {
  std::vector<double> t, v;
};

Columns columns(const DecimatedSeries& series, int axis, bool break_gaps) {
  const std::vector<TimedPoint>& points = series.points();
  double gap = std::numeric_limits<double>::infinity();
  if (break_gaps && points.size() > 2) {
    std::vector<double> steps;
    steps.reserve(points.size() - 1);
    for (size_t i = 1; i < points.size(); ++i) steps.push_back(points[i].t - points[i - 1].t);
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    const double median = steps[steps.size() / 2];
    if (median > 0) gap = 5 * median;
  }
  Columns c;
  c.t.reserve(points.size());
  c.v.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (i > 0 && points[i].t - points[i - 1].t > gap) {
      c.t.push_back(kNaN);
      c.v.push_back(kNaN);
    }
    c.t.push_back(points[i].t);
    c.v.push_back(points[i].p[axis]);
  }
  return c;
}

// X against Y of a series (for the X-Y plane), breaking lines at time gaps as columns() does.
Columns plane(const DecimatedSeries& series, bool break_gaps) {
  Columns x = columns(series, 0, break_gaps), y = columns(series, 1, break_gaps);
  for (size_t i = 0; i < x.v.size(); ++i) {
    if (std::isnan(x.t[i])) y.v[i] = kNaN;
  }
  return {x.v, y.v};
}

std::string event_label(const std::string& text) {
  if (text.size() <= kMaxEventLabel) return text;
  return text.substr(0, kMaxEventLabel - 3) + "...";
}

void add_events(Plot& plot, const PlotData& data, bool labels) {
  for (const auto& [t, text] : data.events) {
    plot.vline(t, palette::kPurple, labels ? event_label(text) : "");
  }
}

std::string join(const std::string& dir, const char* name) {
  return (std::filesystem::path(dir) / name).string();
}

std::string xy_figure(const PlotData& data, const std::string& dir) {
  Plot plot(800, 800, "Ball in the X-Y plane (paper figure 5)", "X (m)", "Y (m)");
  plot.set_equal_aspect(true);
  const Columns truth = plane(data.truth, true);
  const Columns measured = plane(data.measured, false);
  const Columns predicted = plane(data.predicted, true);
  if (!truth.t.empty()) plot.line(truth.t, truth.v, palette::kGreen, "true", 2);
  if (!measured.t.empty()) plot.crosses(measured.t, measured.v, palette::kBlue, "measured", 3);
  if (!predicted.t.empty()) {
    plot.line(predicted.t, predicted.v, palette::kOrange,
              "predicted (h = " + std::to_string(data.predicted_horizon) + ")", 1);
  }
  if (truth.t.empty() && measured.t.empty() && predicted.t.empty()) plot.note(kNoData);
  const std::string path = join(dir, "xy.png");
  plot.save(path);
  return path;
}

std::string y_time_figure(const PlotData& data, const std::string& dir) {
  Plot plot(1100, 500, "Y against time with occlusions (paper figure 6)", "time (s)", "Y (m)");
  bool labelled = false;
  for (const auto& [start, end] : data.occlusions) {
    plot.shade_x(start, end, palette::kShade, labelled ? "" : "occluded");
    labelled = true;
  }
  const Columns truth = columns(data.truth, 1, true);
  const Columns measured = columns(data.measured, 1, false);
  const Columns predicted = columns(data.predicted, 1, false);
  if (!truth.t.empty()) plot.line(truth.t, truth.v, palette::kGreen, "true", 1);
  if (!predicted.t.empty()) {
    plot.circles(predicted.t, predicted.v, palette::kOrange,
                 "predicted (h = " + std::to_string(data.predicted_horizon) + ")", 3);
  }
  if (!measured.t.empty()) plot.crosses(measured.t, measured.v, palette::kBlue, "measured", 3);
  add_events(plot, data, true);
  if (truth.t.empty() && measured.t.empty() && predicted.t.empty()) plot.note(kNoData);
  const std::string path = join(dir, "y_time.png");
  plot.save(path);
  return path;
}

// The value below which half the counts lie, read from the bins (at a bin's centre).
double histogram_median(const std::vector<double>& edges, const std::vector<int64_t>& counts,
                        bool log) {
  int64_t total = 0;
  for (int64_t c : counts) total += c;
  int64_t seen = 0;
  for (size_t i = 0; i < counts.size(); ++i) {
    seen += counts[i];
    if (2 * seen >= total) {
      return log ? std::sqrt(edges[i] * edges[i + 1]) : (edges[i] + edges[i + 1]) / 2;
    }
  }
  return kNaN;
}

std::string latency_figure(const PlotData& data, const std::string& dir) {
  constexpr int kWidth = 900, kPanelHeight = 230;
  std::vector<cv::Mat> panels;
  for (const auto& [stage, histogram] : data.latency_ms) {
    int64_t total = 0;
    for (int64_t c : histogram.counts) total += std::max<int64_t>(0, c);
    const std::vector<double> edges = histogram_edges(histogram);
    const bool log = histogram_is_log(histogram);
    std::string title = stage + ": n = " + std::to_string(total);
    if (total > 0) {
      char median[64];
      std::snprintf(median, sizeof median, ", median ~ %.3g ms",
                    histogram_median(edges, histogram.counts, log));
      title += median;
    }
    Plot plot(kWidth, kPanelHeight, title, "latency (ms)", "count");
    plot.set_log_x(log);
    if (!edges.empty()) {
      std::vector<double> counts(histogram.counts.begin(), histogram.counts.end());
      plot.bars(edges, counts, palette::kBlue);
    }
    if (total == 0) plot.note(kNoData);
    panels.push_back(plot.render());
  }
  if (panels.empty()) {
    Plot plot(kWidth, kPanelHeight + 70, "Latency per stage", "latency (ms)", "count");
    plot.note(kNoData);
    panels.push_back(plot.render());
  }
  cv::Mat image;
  cv::vconcat(panels, image);
  const std::string path = join(dir, "latency.png");
  save_png(image, path);
  return path;
}

std::string arm_figure(const PlotData& data, const std::string& dir) {
  static const char* const kAxes[] = {"X", "Y", "Z"};
  const bool empty = data.arm_target.points().empty() && data.arm_actual.points().empty();
  std::vector<cv::Mat> panels;
  for (int axis = 0; axis < 3; ++axis) {
    Plot plot(1100, axis == 0 ? 300 : 260,
              axis == 0 ? "Arm: targets and tool position (" + std::string(kAxes[axis]) + ")"
                        : std::string(kAxes[axis]),
              axis == 2 ? "time (s)" : "", std::string(kAxes[axis]) + " (m)");
    const Columns actual = columns(data.arm_actual, axis, true);
    const Columns target = columns(data.arm_target, axis, false);
    if (!actual.t.empty()) plot.line(actual.t, actual.v, palette::kBlue, "tool (actual)", 2);
    if (!target.t.empty()) plot.crosses(target.t, target.v, palette::kOrange, "target", 4);
    add_events(plot, data, axis == 0);
    if (empty) plot.note(kNoData);
    panels.push_back(plot.render());
  }
  cv::Mat image;
  cv::vconcat(panels, image);
  const std::string path = join(dir, "arm.png");
  save_png(image, path);
  return path;
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

std::vector<std::string> write_session_plots(const PlotData& data, const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::runtime_error("cannot create directory '" + dir + "': " + error.message());
  return {xy_figure(data, dir), y_time_figure(data, dir), latency_figure(data, dir),
          arm_figure(data, dir)};
}

}  // namespace sg::logger
