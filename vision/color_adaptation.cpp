#include "vision/color_adaptation.hpp"

#include <algorithm>
#include <cmath>

#include "vision/order_statistic.hpp"

namespace sg::vision {
namespace {

constexpr size_t kMaxPixels = 8192;
/// Most pixels a frame's sample aims at: a ball up to about 70 px across is sampled every other
/// pixel (every pixel when under 32 px), a nearer one on a coarser grid of about this many, so
/// its cost does not grow with the ball (it sampled up to 8192 and sorted them). Fewer pixels
/// make the 2 % quantiles noisier: 150 moved half-hidden balls' centres (p95 1.35 -> 1.60 px).
constexpr double kSamplePixels = 300;

/// The configured band [lo, hi] cut to [learned_lo - margin, learned_hi + margin], at least
/// `width` wide where the configured band allows.
void narrow(double conf_lo, double conf_hi, double learned_lo, double learned_hi, double margin,
            double width, double& lo, double& hi) {
  lo = std::max(conf_lo, learned_lo - margin);
  hi = std::min(conf_hi, learned_hi + margin);
  if (hi < lo) lo = hi = std::clamp(0.5 * (learned_lo + learned_hi), conf_lo, conf_hi);
  const double missing = width - (hi - lo);
  if (missing > 0) {
    lo -= missing / 2, hi += missing / 2;
    if (lo < conf_lo) hi = std::min(conf_hi, hi + conf_lo - lo), lo = conf_lo;
    if (hi > conf_hi) lo = std::max(conf_lo, lo - (hi - conf_hi)), hi = conf_hi;
  }
}

}  // namespace

ColorAdaptation::ColorAdaptation(const ColorThresholds& configured,
                                 const ColorAdaptationParams& params)
    : configured_(configured), current_(configured), p_(params) {
  for (auto& band : pixels_) band.resize(kMaxPixels);
  sum_.resize(kMaxPixels);
}

bool ColorAdaptation::sample(const cv::Mat& bgr, const cv::Point2d& centre, double radius) {
  count_ = 0;
  if (bgr.type() != CV_8UC3 || !std::isfinite(centre.x) || !std::isfinite(centre.y) ||
      !std::isfinite(radius) || radius <= 0 || radius > bgr.cols || centre.x < -radius ||
      centre.y < -radius || centre.x > bgr.cols + radius || centre.y > bgr.rows + radius)
    return false;
  const double reach = p_.inner * radius, reach2 = reach * reach;
  // A square grid over the disc of radius `reach`: every other pixel (every one for a small
  // ball), coarser where that would be more than about kSamplePixels.
  const int step = std::max(radius > 16 ? 2 : 1,
                            static_cast<int>(std::lround(reach * std::sqrt(M_PI / kSamplePixels))));
  const int y0 = std::max(0, static_cast<int>(std::ceil(centre.y - reach)));
  const int y1 = std::min(bgr.rows - 1, static_cast<int>(std::floor(centre.y + reach)));
  const int x0 = std::max(0, static_cast<int>(std::ceil(centre.x - reach)));
  const int x1 = std::min(bgr.cols - 1, static_cast<int>(std::floor(centre.x + reach)));
  const int min_sum = std::max(1, configured_.min_intensity);  // a black pixel has no colour
  // Locals, not members, in the loops: a store through a float* may not change them.
  float *r = pixels_[0].data(), *g = pixels_[1].data(), *b = pixels_[2].data();
  float* sum = sum_.data();
  size_t n = 0;
  for (int y = y0; y <= y1; y += step) {
    const auto* row = bgr.ptr<uint8_t>(y);
    const double dy = y - centre.y, dx_max2 = reach2 - dy * dy;
    for (int x = x0; x <= x1 && n < kMaxPixels; x += step) {
      const double dx = x - centre.x;
      const uint8_t* px = row + 3 * x;
      const int s = px[0] + px[1] + px[2];
      if (dx * dx > dx_max2 || s < min_sum) continue;
      r[n] = px[2], g[n] = px[1], b[n] = px[0], sum[n++] = static_cast<float>(s);
    }
  }
  // Then the chromaticities, a loop the compiler vectorizes (exact: IEEE division in each lane).
  for (size_t i = 0; i < n; ++i) r[i] /= sum[i], g[i] /= sum[i], b[i] /= sum[i];
  count_ = n;
  // Never an empty sample, whatever min_pixels says: quantile_of needs a pixel.
  return count_ > 0 && static_cast<int>(count_) >= p_.min_pixels;
}

bool ColorAdaptation::learn(const cv::Mat& bgr, const cv::Point2d& centre, double radius) {
  if (!p_.enabled || !sample(bgr, centre, radius)) return false;
  const double a = samples_ == 0 ? 1.0 : std::max(p_.rate, 1.0 / (samples_ + 1));
  for (size_t b = 0; b < 3; ++b) {
    const std::span<float> band(pixels_[b].data(), count_);
    const auto [q_lo, q_hi] = quantiles_of(band, p_.quantile);
    low_[b] += a * (q_lo - low_[b]);
    high_[b] += a * (q_hi - high_[b]);
  }
  ++samples_;
  if (samples_ < p_.min_samples) return false;
  const ColorThresholds before = current_;
  update_current();
  return before.r_min != current_.r_min || before.r_max != current_.r_max ||
         before.g_min != current_.g_min || before.g_max != current_.g_max ||
         before.b_min != current_.b_min || before.b_max != current_.b_max;
}

void ColorAdaptation::update_current() {
  const ColorThresholds& c = configured_;
  narrow(c.r_min, c.r_max, low_[0], high_[0], p_.margin, p_.min_width, current_.r_min,
         current_.r_max);
  narrow(c.g_min, c.g_max, low_[1], high_[1], p_.margin, p_.min_width, current_.g_min,
         current_.g_max);
  narrow(c.b_min, c.b_max, low_[2], high_[2], p_.margin, p_.min_width, current_.b_min,
         current_.b_max);
}

bool ColorAdaptation::forget() {
  const bool narrowed = samples_ >= p_.min_samples;
  samples_ = 0;
  low_ = {}, high_ = {};
  current_ = configured_;
  return narrowed;
}

}  // namespace sg::vision
