#pragma once

/// A small 2D plot drawn with OpenCV, for the session report's PNG figures (Debian ships no C++
/// plotting library; OpenCV draws lines, markers and Hershey text well enough). Axis ranges are
/// automatic, padded out to "nice" ticks (steps of 1, 2 or 5 times a power of ten); a legend
/// lists every labelled series; save() writes a PNG.
///
///     Plot plot(800, 500, "Y against time", "time (s)", "Y (m)");
///     plot.shade_x(3.0, 4.5, palette::kShade, "occluded");
///     plot.line(ts, truth_y, palette::kGreen, "true");
///     plot.crosses(ts, measured_y, palette::kBlue, "measured");
///     plot.circles(ts, predicted_y, palette::kOrange, "predicted");
///     plot.vline(5.2, palette::kPurple, "q2 grasping");
///     plot.save("y_time.png");  // throws std::runtime_error naming the path on failure
///
/// Several plots stack into one figure with cv::vconcat of their render()s and save_png().
///
/// Robustness: non-finite values (NaN, infinities) are skipped, and a NaN in a line breaks it
/// into separate pieces; with no data at all the axes show 0..1; a zero range (a single point,
/// a constant series) is widened around the value. Nothing divides by zero.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sg::logger {

/// Colours (OpenCV's BGR order) for plots: the "tab10" hues, plus a light shade for bands.
namespace palette {
inline const cv::Scalar kBlue(180, 119, 31);
inline const cv::Scalar kOrange(14, 127, 255);
inline const cv::Scalar kGreen(44, 160, 44);
inline const cv::Scalar kRed(40, 39, 214);
inline const cv::Scalar kPurple(189, 103, 148);
inline const cv::Scalar kGrey(127, 127, 127);
inline const cv::Scalar kBlack(30, 30, 30);
/// Light orange for shaded bands (occlusions); drawn flat, so its exact value shows in the PNG.
inline const cv::Scalar kShade(181, 228, 255);
/// Notes over the axes ("no data"): a muted red.
inline const cv::Scalar kNote(70, 70, 190);
/// The figure's background.
inline const cv::Scalar kBackground(255, 255, 255);
}  // namespace palette

/// Writes `image` as a PNG at `png_path` (cv::imwrite). Returns true; throws std::runtime_error
/// naming the path when the file cannot be written.
bool save_png(const cv::Mat& image, const std::string& png_path);

/// One set of axes with series, bands, markers, a legend, a title and axis labels.
class Plot {
 public:
  /// A `width` x `height` pixel plot (each at least 160 x 120; smaller requests are raised).
  Plot(int width, int height, std::string title, std::string x_label, std::string y_label);

  /// A polyline through (xs[i], ys[i]); a non-finite value breaks the line there. Uses the
  /// shorter of xs and ys. An empty `label` leaves the series out of the legend.
  void line(const std::vector<double>& xs, const std::vector<double>& ys, const cv::Scalar& colour,
            const std::string& label = "", int thickness = 2);
  /// An "x" marker of half-size `size` pixels at each point.
  void crosses(const std::vector<double>& xs, const std::vector<double>& ys,
               const cv::Scalar& colour, const std::string& label = "", int size = 4);
  /// An open circle of radius `radius` pixels at each point.
  void circles(const std::vector<double>& xs, const std::vector<double>& ys,
               const cv::Scalar& colour, const std::string& label = "", int radius = 4);
  /// A vertical band over x in [x0, x1], the full height of the axes (at least one pixel wide),
  /// drawn flat under everything else.
  void shade_x(double x0, double x1, const cv::Scalar& colour, const std::string& label = "");
  /// A dashed vertical marker at `x` with `text` written near its top (empty: no text); texts
  /// of successive markers are staggered over three rows. Not in the legend.
  void vline(double x, const cv::Scalar& colour, const std::string& text = "");
  /// A histogram: bar i spans [edges[i], edges[i + 1]) with height counts[i];
  /// edges.size() must be counts.size() + 1 (otherwise nothing is drawn). The y range
  /// includes 0.
  void bars(const std::vector<double>& edges, const std::vector<double>& counts,
            const cv::Scalar& colour, const std::string& label = "");
  /// Centred text over the axes, e.g. "no data".
  void note(const std::string& text);

  /// One metre (unit) is as long across as up: the narrower range is widened about its centre.
  void set_equal_aspect(bool on) { equal_aspect_ = on; }
  /// Logarithmic x axis (decades); values <= 0 are skipped. Ignored with equal aspect.
  void set_log_x(bool on) { log_x_ = on; }
  /// Fixed ranges instead of automatic ones (lo < hi, finite; otherwise ignored).
  void set_x_range(double lo, double hi);
  void set_y_range(double lo, double hi);

  /// The image: white background, ticks and grid, series, legend, title and labels.
  cv::Mat render() const;
  /// render() written as a PNG; returns true, throws std::runtime_error naming the path on
  /// failure.
  bool save(const std::string& png_path) const;

  /// Where data point (x, y) lands in render()'s image, in pixels (x right, y down), given the
  /// series added so far. For tests and annotations.
  cv::Point2d pixel(double x, double y) const;
  /// The axes' rectangle inside the image.
  cv::Rect plot_area() const;
  /// The x and y ticks render() would draw (data units), given the series added so far.
  std::vector<double> x_ticks() const;
  std::vector<double> y_ticks() const;

  /// Ticks at a 1-2-5 step covering [lo, hi] with at most `max_ticks` ticks (at least 2):
  /// the first tick is <= lo, the last >= hi. 0..1 gives 0, 0.2, ..., 1; 0..7 gives 0, 2, ..., 8.
  /// lo == hi (or non-finite input) is widened first, so there are always at least 2 ticks.
  static std::vector<double> nice_ticks(double lo, double hi, int max_ticks = 7);

 private:
  enum class Kind { kLine, kCrosses, kCircles, kBars, kShade, kVline };
  struct Series {
    Kind kind;
    std::vector<double> xs, ys;  // kBars: xs = edges, ys = counts; kShade/kVline: xs only
    cv::Scalar colour;
    std::string label;
    int size;
  };
  struct Axis {
    double lo = 0, hi = 1;      // in plotted units (log10 of x for a log axis)
    std::vector<double> ticks;  // in plotted units
    int decimals = 0;           // for tick labels of a linear axis
    bool log = false;
  };
  struct Layout {
    cv::Rect area;
    Axis x, y;
  };

  Layout layout() const;
  double x_value(double x) const;  // data -> plotted units (log10 on a log axis; NaN if <= 0)

  int width_, height_;
  std::string title_, x_label_, y_label_;
  std::vector<Series> series_;
  std::vector<std::string> notes_;
  bool equal_aspect_ = false;
  bool log_x_ = false;
  bool fixed_x_ = false, fixed_y_ = false;
  double x_lo_ = 0, x_hi_ = 1, y_lo_ = 0, y_hi_ = 1;
};

}  // namespace sg::logger
