#include "logger/plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

namespace sg::logger {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTickScale = 0.42;
constexpr double kLabelScale = 0.5;
constexpr double kTitleScale = 0.6;
constexpr int kShift = 4;  // sub-pixel bits for OpenCV drawing
constexpr double kShiftScale = 1 << kShift;
const cv::Scalar kText(40, 40, 40);
const cv::Scalar kFrame(90, 90, 90);
const cv::Scalar kGrid(228, 228, 228);
constexpr double kEps = 1e-9;

double power_of_ten(int e) { return std::pow(10.0, e); }

// A 1-2-5 step: step = multiplier * 10^exponent.
struct Step {
  int multiplier = 1;
  int exponent = 0;
  // k steps, computed so that e.g. 3 * 0.2 is exactly the double nearest 0.6.
  double at(double k) const {
    return exponent < 0 ? k * multiplier / power_of_ten(-exponent)
                        : k * multiplier * power_of_ten(exponent);
  }
  double size() const { return at(1); }
};

// Widens [lo, hi] when empty, reversed, degenerate or non-finite.
void widen(double& lo, double& hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) {
    lo = 0;
    hi = 1;
    return;
  }
  if (lo > hi) std::swap(lo, hi);
  const double magnitude = std::max(std::abs(lo), std::abs(hi));
  if (hi - lo <= magnitude * 1e-12) {
    const double pad = magnitude > 0 ? magnitude * 0.1 : 1.0;
    lo -= pad;
    hi += pad;
  }
}

// Ticks covering [lo, hi] (first <= lo, last >= hi) for a step.
std::pair<double, double> covering(double lo, double hi, const Step& step) {
  const double s = step.size();
  return {std::floor(lo / s + kEps), std::ceil(hi / s - kEps)};
}

// The smallest 1-2-5 step whose covering ticks number at most max_ticks. Requires lo < hi.
Step nice_step(double lo, double hi, int max_ticks) {
  max_ticks = std::max(2, max_ticks);
  Step step;
  step.exponent = static_cast<int>(std::floor(std::log10((hi - lo) / max_ticks))) - 1;
  for (int i = 0; i < 40; ++i) {
    for (int m : {1, 2, 5}) {
      step.multiplier = m;
      auto [k0, k1] = covering(lo, hi, step);
      if (k1 - k0 + 1 <= max_ticks) return step;
    }
    ++step.exponent;
  }
  return step;
}

int decimals_for(const Step& step) { return step.exponent < 0 ? -step.exponent : 0; }

std::string tick_label(double value, int decimals, bool log) {
  char buffer[64];
  if (log) {
    std::snprintf(buffer, sizeof buffer, "%g", std::pow(10.0, value));
  } else if (std::abs(value) >= 1e6 || decimals > 6) {
    std::snprintf(buffer, sizeof buffer, "%g", value);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  }
  std::string text = buffer;
  if (text.size() > 1 && text[0] == '-' && text.find_first_not_of("-0.") == std::string::npos) {
    text.erase(0, 1);  // "-0.0" -> "0.0"
  }
  return text;
}

cv::Size text_size(const std::string& text, double scale, int* baseline = nullptr) {
  int base = 0;
  cv::Size size = cv::getTextSize(text, kFont, scale, 1, &base);
  if (baseline != nullptr) *baseline = base;
  return size;
}

void put_text(cv::Mat& image, const std::string& text, cv::Point origin, double scale,
              const cv::Scalar& colour, int thickness = 1) {
  cv::putText(image, text, origin, kFont, scale, colour, thickness, cv::LINE_AA);
}

// Pixel coordinates for OpenCV's shifted drawing, clamped far outside so ints cannot overflow.
cv::Point shifted(double x, double y) {
  auto clamp = [](double v) { return std::clamp(v, -1e5, 1e5); };
  return {static_cast<int>(std::lround(clamp(x) * kShiftScale)),
          static_cast<int>(std::lround(clamp(y) * kShiftScale))};
}

}  // namespace

bool save_png(const cv::Mat& image, const std::string& png_path) {
  bool written = false;
  std::string reason = "cv::imwrite failed";
  try {
    written = cv::imwrite(png_path, image);
  } catch (const cv::Exception& e) {
    reason = e.what();
  }
  if (!written) throw std::runtime_error("cannot write PNG '" + png_path + "': " + reason);
  return true;
}

Plot::Plot(int width, int height, std::string title, std::string x_label, std::string y_label)
    : width_(std::max(width, 160)),
      height_(std::max(height, 120)),
      title_(std::move(title)),
      x_label_(std::move(x_label)),
      y_label_(std::move(y_label)) {}

void Plot::line(const std::vector<double>& xs, const std::vector<double>& ys,
                const cv::Scalar& colour, const std::string& label, int thickness) {
  const size_t n = std::min(xs.size(), ys.size());
  series_.push_back({Kind::kLine,
                     {xs.begin(), xs.begin() + n},
                     {ys.begin(), ys.begin() + n},
                     colour,
                     label,
                     std::max(1, thickness)});
}

void Plot::crosses(const std::vector<double>& xs, const std::vector<double>& ys,
                   const cv::Scalar& colour, const std::string& label, int size) {
  const size_t n = std::min(xs.size(), ys.size());
  series_.push_back({Kind::kCrosses,
                     {xs.begin(), xs.begin() + n},
                     {ys.begin(), ys.begin() + n},
                     colour,
                     label,
                     std::max(1, size)});
}

void Plot::circles(const std::vector<double>& xs, const std::vector<double>& ys,
                   const cv::Scalar& colour, const std::string& label, int radius) {
  const size_t n = std::min(xs.size(), ys.size());
  series_.push_back({Kind::kCircles,
                     {xs.begin(), xs.begin() + n},
                     {ys.begin(), ys.begin() + n},
                     colour,
                     label,
                     std::max(1, radius)});
}

void Plot::shade_x(double x0, double x1, const cv::Scalar& colour, const std::string& label) {
  if (!std::isfinite(x0) || !std::isfinite(x1)) return;
  if (x0 > x1) std::swap(x0, x1);
  series_.push_back({Kind::kShade, {x0, x1}, {}, colour, label, 0});
}

void Plot::vline(double x, const cv::Scalar& colour, const std::string& text) {
  if (!std::isfinite(x)) return;
  series_.push_back({Kind::kVline, {x}, {}, colour, text, 1});
}

void Plot::bars(const std::vector<double>& edges, const std::vector<double>& counts,
                const cv::Scalar& colour, const std::string& label) {
  if (counts.empty() || edges.size() != counts.size() + 1) return;
  series_.push_back({Kind::kBars, edges, counts, colour, label, 0});
}

void Plot::note(const std::string& text) { notes_.push_back(text); }

void Plot::set_x_range(double lo, double hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) return;
  fixed_x_ = true;
  x_lo_ = lo;
  x_hi_ = hi;
}

void Plot::set_y_range(double lo, double hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) return;
  fixed_y_ = true;
  y_lo_ = lo;
  y_hi_ = hi;
}

std::vector<double> Plot::nice_ticks(double lo, double hi, int max_ticks) {
  widen(lo, hi);
  const Step step = nice_step(lo, hi, max_ticks);
  auto [k0, k1] = covering(lo, hi, step);
  std::vector<double> ticks;
  for (double k = k0; k <= k1; ++k) ticks.push_back(step.at(k) == 0 ? 0.0 : step.at(k));
  return ticks;
}

double Plot::x_value(double x) const {
  if (!log_x_ || equal_aspect_) return x;
  return x > 0 ? std::log10(x) : std::numeric_limits<double>::quiet_NaN();
}

Plot::Layout Plot::layout() const {
  // Data extents in plotted units.
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min;
  double y_min = x_min, y_max = -x_min;
  auto take_x = [&](double x) {
    x = x_value(x);
    if (!std::isfinite(x)) return false;
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
    return true;
  };
  auto take_y = [&](double y) {
    if (!std::isfinite(y)) return;
    y_min = std::min(y_min, y);
    y_max = std::max(y_max, y);
  };
  for (const Series& s : series_) {
    switch (s.kind) {
      case Kind::kLine:
      case Kind::kCrosses:
      case Kind::kCircles:
        for (size_t i = 0; i < s.xs.size(); ++i) {
          if (!std::isfinite(s.ys[i]) || !std::isfinite(x_value(s.xs[i]))) continue;
          take_x(s.xs[i]);
          take_y(s.ys[i]);
        }
        break;
      case Kind::kBars:
        for (double e : s.xs) take_x(e);
        take_y(0);
        for (double c : s.ys) take_y(c * 1.05);  // headroom above the tallest bar
        break;
      case Kind::kShade:
      case Kind::kVline:
        for (double x : s.xs) take_x(x);
        break;
    }
  }
  const bool log_x = log_x_ && !equal_aspect_;
  if (fixed_x_) {
    x_min = x_value(x_lo_);
    x_max = x_value(x_hi_);
  }
  if (fixed_y_) {
    y_min = y_lo_;
    y_max = y_hi_;
  }
  if (!(x_min <= x_max)) x_min = 0, x_max = 1;
  if (!(y_min <= y_max)) y_min = 0, y_max = 1;

  Layout layout;
  const int top = title_.empty() ? 14 : 38;
  const int bottom = x_label_.empty() ? 30 : 52;
  const int right = 18;
  const int area_height = std::max(20, height_ - top - bottom);

  // Auto ranges pad out to the covering ticks; fixed ranges keep their ends, ticks inside.
  auto make_linear = [](Axis& axis, double lo, double hi, int max_ticks, bool pad) {
    widen(lo, hi);
    const Step step = nice_step(lo, hi, max_ticks);
    axis.decimals = decimals_for(step);
    auto [k0, k1] = covering(lo, hi, step);
    if (pad) {
      lo = step.at(k0);
      hi = step.at(k1);
    } else {
      k0 = std::ceil(lo / step.size() - kEps);
      k1 = std::floor(hi / step.size() + kEps);
    }
    axis.lo = lo;
    axis.hi = hi;
    axis.ticks.clear();
    for (double k = k0; k <= k1; ++k) axis.ticks.push_back(step.at(k) == 0 ? 0.0 : step.at(k));
  };
  make_linear(layout.y, y_min, y_max, std::clamp(area_height / 45, 2, 10), !fixed_y_);

  // The left margin fits the widest y tick label.
  int label_width = 0;
  for (double t : layout.y.ticks) {
    label_width =
        std::max(label_width, text_size(tick_label(t, layout.y.decimals, false), kTickScale).width);
  }
  const int left = std::min(width_ / 3, label_width + 14 + (y_label_.empty() ? 0 : 24));
  layout.area = cv::Rect(left, top, std::max(20, width_ - left - right), area_height);

  const int max_x_ticks = std::clamp(layout.area.width / 75, 2, 12);
  if (log_x) {
    Axis& x = layout.x;
    x.log = true;
    double lo = std::floor(x_min + kEps), hi = std::ceil(x_max - kEps);
    if (fixed_x_) lo = x_min, hi = x_max;
    if (!(hi > lo)) hi = lo + 1;
    x.lo = lo;
    x.hi = hi;
    const double decades = std::ceil(hi) - std::floor(lo);
    const double every = std::max(1.0, std::ceil(decades / max_x_ticks));
    for (double k = std::ceil(lo - kEps); k <= hi + kEps; k += every) x.ticks.push_back(k);
  } else {
    make_linear(layout.x, x_min, x_max, max_x_ticks, !fixed_x_);
  }

  if (equal_aspect_) {
    const double ux = (layout.x.hi - layout.x.lo) / layout.area.width;
    const double uy = (layout.y.hi - layout.y.lo) / layout.area.height;
    Axis& grow = ux > uy ? layout.y : layout.x;
    const double units = std::max(ux, uy) * (ux > uy ? layout.area.height : layout.area.width);
    const double centre = (grow.lo + grow.hi) / 2;
    const int max_ticks = ux > uy ? std::clamp(layout.area.height / 45, 2, 10) : max_x_ticks;
    make_linear(grow, centre - units / 2, centre + units / 2, max_ticks, false);
  }
  return layout;
}

cv::Rect Plot::plot_area() const { return layout().area; }

std::vector<double> Plot::x_ticks() const {
  Layout l = layout();
  if (!l.x.log) return l.x.ticks;
  std::vector<double> ticks;
  for (double t : l.x.ticks) ticks.push_back(std::pow(10.0, t));
  return ticks;
}

std::vector<double> Plot::y_ticks() const { return layout().y.ticks; }

cv::Point2d Plot::pixel(double x, double y) const {
  const Layout l = layout();
  const double xv = x_value(x);
  return {l.area.x + (xv - l.x.lo) / (l.x.hi - l.x.lo) * l.area.width,
          l.area.y + l.area.height - (y - l.y.lo) / (l.y.hi - l.y.lo) * l.area.height};
}

cv::Mat Plot::render() const {
  const Layout l = layout();
  cv::Mat image(height_, width_, CV_8UC3, palette::kBackground);
  cv::Mat area = image(l.area);  // drawing here clips to the axes
  const double w = l.area.width, h = l.area.height;
  auto lx = [&](double x) { return (x_value(x) - l.x.lo) / (l.x.hi - l.x.lo) * w; };
  auto ly = [&](double y) { return h - (y - l.y.lo) / (l.y.hi - l.y.lo) * h; };
  auto finite = [&](double x, double y) { return std::isfinite(y) && std::isfinite(x_value(x)); };

  // Bands first, then the grid, then data.
  for (const Series& s : series_) {
    if (s.kind != Kind::kShade) continue;
    double a = lx(s.xs[0]), b = lx(s.xs[1]);
    if (!std::isfinite(a)) a = 0;  // a log axis with x0 <= 0: from the left edge
    if (!std::isfinite(b)) continue;
    const int x0 = static_cast<int>(std::floor(std::clamp(a, -1.0, w + 1)));
    const int x1 = std::max(x0 + 1, static_cast<int>(std::ceil(std::clamp(b, -1.0, w + 1))));
    cv::rectangle(area, cv::Point(x0, 0), cv::Point(x1 - 1, l.area.height - 1), s.colour,
                  cv::FILLED);
  }
  for (double t : l.x.ticks) {
    const double px = (t - l.x.lo) / (l.x.hi - l.x.lo) * w;
    cv::line(area, shifted(px, 0), shifted(px, h), kGrid, 1, cv::LINE_8, kShift);
  }
  for (double t : l.y.ticks) {
    const double py = h - (t - l.y.lo) / (l.y.hi - l.y.lo) * h;
    cv::line(area, shifted(0, py), shifted(w, py), kGrid, 1, cv::LINE_8, kShift);
  }

  for (const Series& s : series_) {
    if (s.kind != Kind::kBars) continue;
    const cv::Scalar outline = s.colour * 0.7;
    for (size_t i = 0; i < s.ys.size(); ++i) {
      const double a = lx(s.xs[i]), b = lx(s.xs[i + 1]), top = ly(s.ys[i]);
      if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(top) || !(s.ys[i] > 0)) {
        continue;
      }
      const cv::Point p0 = shifted(std::min(a, b), top), p1 = shifted(std::max(a, b), ly(0));
      cv::rectangle(area, p0, p1, s.colour, cv::FILLED, cv::LINE_8, kShift);
      cv::rectangle(area, p0, p1, outline, 1, cv::LINE_8, kShift);
    }
  }

  for (const Series& s : series_) {
    if (s.kind == Kind::kLine) {
      std::vector<cv::Point> piece;
      auto flush = [&] {
        if (piece.size() == 1) {
          cv::circle(area, piece[0], static_cast<int>(s.size * kShiftScale / 2), s.colour,
                     cv::FILLED, cv::LINE_AA, kShift);
        } else if (piece.size() > 1) {
          cv::polylines(area, piece, false, s.colour, s.size, cv::LINE_AA, kShift);
        }
        piece.clear();
      };
      for (size_t i = 0; i < s.xs.size(); ++i) {
        if (!finite(s.xs[i], s.ys[i])) {
          flush();
          continue;
        }
        piece.push_back(shifted(lx(s.xs[i]), ly(s.ys[i])));
      }
      flush();
    } else if (s.kind == Kind::kCircles) {
      for (size_t i = 0; i < s.xs.size(); ++i) {
        if (!finite(s.xs[i], s.ys[i])) continue;
        cv::circle(area, shifted(lx(s.xs[i]), ly(s.ys[i])), static_cast<int>(s.size * kShiftScale),
                   s.colour, 1, cv::LINE_AA, kShift);
      }
    }
  }
  for (const Series& s : series_) {
    if (s.kind != Kind::kCrosses) continue;
    for (size_t i = 0; i < s.xs.size(); ++i) {
      if (!finite(s.xs[i], s.ys[i])) continue;
      const double x = lx(s.xs[i]), y = ly(s.ys[i]), d = s.size;
      cv::line(area, shifted(x - d, y - d), shifted(x + d, y + d), s.colour, 1, cv::LINE_AA,
               kShift);
      cv::line(area, shifted(x - d, y + d), shifted(x + d, y - d), s.colour, 1, cv::LINE_AA,
               kShift);
    }
  }

  // Vertical markers: dashed, with staggered texts near the top.
  int marker = 0;
  for (const Series& s : series_) {
    if (s.kind != Kind::kVline) continue;
    const double x = lx(s.xs[0]);
    if (!std::isfinite(x)) continue;
    const int px = static_cast<int>(std::lround(std::clamp(x, -10.0, w + 10)));
    for (int y = 0; y < l.area.height; y += 10) {
      cv::line(area, cv::Point(px, y), cv::Point(px, std::min(l.area.height - 1, y + 6)), s.colour,
               1, cv::LINE_8);
    }
    if (!s.label.empty()) {
      int base = 0;
      const cv::Size size = text_size(s.label, kTickScale, &base);
      const int row = marker++ % 3;
      const int y = 4 + size.height + row * (size.height + base + 6);
      int x0 = static_cast<int>(x) + 4;
      if (x0 + size.width > l.area.width - 2) x0 = static_cast<int>(x) - 4 - size.width;
      cv::rectangle(area, cv::Point(x0 - 1, y - size.height - 2),
                    cv::Point(x0 + size.width + 1, y + base), palette::kBackground, cv::FILLED);
      put_text(area, s.label, cv::Point(x0, y), kTickScale, s.colour);
    }
  }

  // Frame, ticks and tick labels.
  cv::rectangle(image, l.area, kFrame, 1);
  const int bottom_y = l.area.y + l.area.height;
  for (double t : l.x.ticks) {
    const int px = l.area.x + static_cast<int>(std::lround((t - l.x.lo) / (l.x.hi - l.x.lo) * w));
    cv::line(image, cv::Point(px, bottom_y), cv::Point(px, bottom_y + 4), kFrame, 1);
    const std::string text = tick_label(t, l.x.decimals, l.x.log);
    const cv::Size size = text_size(text, kTickScale);
    put_text(image, text, cv::Point(px - size.width / 2, bottom_y + 8 + size.height), kTickScale,
             kText);
  }
  for (double t : l.y.ticks) {
    const int py =
        l.area.y + static_cast<int>(std::lround(h - (t - l.y.lo) / (l.y.hi - l.y.lo) * h));
    cv::line(image, cv::Point(l.area.x - 4, py), cv::Point(l.area.x, py), kFrame, 1);
    const std::string text = tick_label(t, l.y.decimals, false);
    const cv::Size size = text_size(text, kTickScale);
    put_text(image, text, cv::Point(l.area.x - 7 - size.width, py + size.height / 2), kTickScale,
             kText);
  }

  // Legend in the corner of the axes that hides the fewest data points.
  std::vector<const Series*> entries;
  for (const Series& s : series_) {
    if (!s.label.empty() && s.kind != Kind::kVline) entries.push_back(&s);
  }
  if (!entries.empty()) {
    const int row_height = 18, sample = 26;
    int text_width = 0;
    for (const Series* s : entries) {
      text_width = std::max(text_width, text_size(s->label, kTickScale).width);
    }
    const cv::Size box(
        std::min(l.area.width - 16, sample + 14 + text_width),
        std::min(l.area.height - 16, row_height * static_cast<int>(entries.size()) + 8));
    const std::array<cv::Point, 4> corners = {
        cv::Point(l.area.width - 8 - box.width, 8), cv::Point(8, 8),
        cv::Point(l.area.width - 8 - box.width, l.area.height - 8 - box.height),
        cv::Point(8, l.area.height - 8 - box.height)};
    int best = 0;
    int64_t best_hidden = std::numeric_limits<int64_t>::max();
    for (int c = 0; c < 4; ++c) {
      const cv::Rect rect(corners[c], box);
      int64_t hidden = 0;
      for (const Series& s : series_) {
        if (s.kind != Kind::kLine && s.kind != Kind::kCrosses && s.kind != Kind::kCircles) {
          continue;
        }
        for (size_t i = 0; i < s.xs.size(); ++i) {
          if (!finite(s.xs[i], s.ys[i])) continue;
          const double x = lx(s.xs[i]), y = ly(s.ys[i]);
          hidden +=
              x >= rect.x && x <= rect.x + rect.width && y >= rect.y && y <= rect.y + rect.height;
        }
      }
      for (const Series& s : series_) {  // markers and their texts: avoid them
        if (s.kind != Kind::kVline) continue;
        const double x = lx(s.xs[0]);
        if (std::isfinite(x) && x >= rect.x - 60 && x <= rect.x + rect.width) hidden += 50;
      }
      for (const Series& s : series_) {
        if (s.kind != Kind::kBars) continue;
        for (size_t i = 0; i < s.ys.size(); ++i) {
          const double x = lx((s.xs[i] + s.xs[i + 1]) / 2), y = ly(s.ys[i]);
          if (std::isfinite(x) && std::isfinite(y) && x >= rect.x && x <= rect.x + rect.width &&
              y <= rect.y + rect.height) {
            hidden += 4;
          }
        }
      }
      if (hidden < best_hidden) best_hidden = hidden, best = c;
    }
    const cv::Rect rect(corners[best], box);
    cv::rectangle(area, rect, palette::kBackground, cv::FILLED);
    cv::rectangle(area, rect, cv::Scalar(180, 180, 180), 1);
    for (size_t i = 0; i < entries.size(); ++i) {
      const Series& s = *entries[i];
      const int cy = rect.y + 4 + row_height * static_cast<int>(i) + row_height / 2;
      const int x0 = rect.x + 6, x1 = x0 + sample, cx = (x0 + x1) / 2;
      switch (s.kind) {
        case Kind::kLine:
          cv::line(area, cv::Point(x0, cy), cv::Point(x1, cy), s.colour, s.size, cv::LINE_AA);
          break;
        case Kind::kCrosses:
          cv::line(area, cv::Point(cx - 4, cy - 4), cv::Point(cx + 4, cy + 4), s.colour, 1,
                   cv::LINE_AA);
          cv::line(area, cv::Point(cx - 4, cy + 4), cv::Point(cx + 4, cy - 4), s.colour, 1,
                   cv::LINE_AA);
          break;
        case Kind::kCircles:
          cv::circle(area, cv::Point(cx, cy), 4, s.colour, 1, cv::LINE_AA);
          break;
        case Kind::kBars:
        case Kind::kShade:
        case Kind::kVline:
          cv::rectangle(area, cv::Point(x0 + 4, cy - 5), cv::Point(x1 - 4, cy + 5), s.colour,
                        cv::FILLED);
          break;
      }
      put_text(area, s.label, cv::Point(x1 + 8, cy + 5), kTickScale, kText);
    }
  }

  // Notes centred over the axes.
  for (size_t i = 0; i < notes_.size(); ++i) {
    const cv::Size size = text_size(notes_[i], 0.8);
    const int y = l.area.height / 2 + size.height / 2 + static_cast<int>(i) * (size.height + 12) -
                  static_cast<int>(notes_.size() - 1) * (size.height + 12) / 2;
    put_text(area, notes_[i], cv::Point((l.area.width - size.width) / 2, y), 0.8, palette::kNote,
             2);
  }

  // Title, x label, rotated y label.
  if (!title_.empty()) {
    const cv::Size size = text_size(title_, kTitleScale);
    put_text(image, title_, cv::Point(std::max(2, (width_ - size.width) / 2), 12 + size.height),
             kTitleScale, kText);
  }
  if (!x_label_.empty()) {
    const cv::Size size = text_size(x_label_, kLabelScale);
    put_text(image, x_label_,
             cv::Point(l.area.x + std::max(0, (l.area.width - size.width) / 2), height_ - 10),
             kLabelScale, kText);
  }
  if (!y_label_.empty()) {
    int base = 0;
    const cv::Size size = text_size(y_label_, kLabelScale, &base);
    cv::Mat text(size.height + base + 4, size.width + 4, CV_8UC3, palette::kBackground);
    put_text(text, y_label_, cv::Point(2, size.height + 2), kLabelScale, kText);
    cv::Mat rotated;
    cv::rotate(text, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int rows = std::min(rotated.rows, height_), cols = std::min(rotated.cols, width_);
    const int y0 = std::clamp(l.area.y + (l.area.height - rows) / 2, 0, height_ - rows);
    rotated(cv::Rect(0, 0, cols, rows)).copyTo(image(cv::Rect(4, y0, cols, rows)));
  }
  return image;
}

bool Plot::save(const std::string& png_path) const { return save_png(render(), png_path); }

}  // namespace sg::logger
