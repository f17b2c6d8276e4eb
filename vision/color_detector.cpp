#include "vision/color_detector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace sg::vision {
namespace {

int64_t fixed(double v) { return std::llround(std::clamp(v, 0.0, 1.0) * 65536.0); }

}  // namespace

ColorDetector::ColorDetector(const ColorThresholds& t)
    : t_(t),
      r_lo_(fixed(t.r_min)),
      r_hi_(fixed(t.r_max)),
      g_lo_(fixed(t.g_min)),
      g_hi_(fixed(t.g_max)),
      b_lo_(fixed(t.b_min)),
      b_hi_(fixed(t.b_max)),
      min_sum_(std::max(1, t.min_intensity)) {
  for (double v : {t.r_min, t.r_max, t.g_min, t.g_max, t.b_min, t.b_max}) {
    if (!(v >= 0.0 && v <= 1.0)) throw std::invalid_argument("colour thresholds must be in [0, 1]");
  }
  if (t.r_min > t.r_max || t.g_min > t.g_max || t.b_min > t.b_max)
    throw std::invalid_argument("colour thresholds: a minimum is above its maximum");
}

ColorThresholds ColorThresholds::learn(const cv::Mat& bgr, const cv::Rect& roi, double margin,
                                       double keep) {
  if (bgr.type() != CV_8UC3) throw std::invalid_argument("learn: the image must be 8-bit BGR");
  const cv::Rect inside = roi & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (inside.area() == 0) throw std::invalid_argument("learn: the region is outside the image");
  std::vector<double> r, g, b;
  int min_sum = 765;
  for (int y = inside.y; y < inside.y + inside.height; ++y) {
    for (int x = inside.x; x < inside.x + inside.width; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      const int sum = p[0] + p[1] + p[2];
      if (sum == 0) continue;
      b.push_back(p[0] / double(sum));
      g.push_back(p[1] / double(sum));
      r.push_back(p[2] / double(sum));
      min_sum = std::min(min_sum, sum);
    }
  }
  if (r.empty()) throw std::invalid_argument("learn: the region holds only black pixels");
  auto range = [&](std::vector<double>& v, double& lo, double& hi) {
    std::sort(v.begin(), v.end());
    const double cut = (1.0 - keep) / 2;
    lo = std::max(0.0, v[static_cast<size_t>(cut * (v.size() - 1))] - margin);
    hi = std::min(1.0, v[static_cast<size_t>((1.0 - cut) * (v.size() - 1))] + margin);
  };
  ColorThresholds t;
  range(r, t.r_min, t.r_max);
  range(g, t.g_min, t.g_max);
  range(b, t.b_min, t.b_max);
  t.min_intensity = std::max(30, min_sum / 2);
  return t;
}

namespace {

/// The row kernel, one clone per instruction set; the loader picks the best the CPU has.
__attribute__((target_clones("avx2", "default"))) void classify_row(
    const uint8_t* __restrict bgr, int n, uint8_t* __restrict mask, int32_t r_lo, int32_t r_hi,
    int32_t g_lo, int32_t g_hi, int32_t b_lo, int32_t b_hi, int32_t min_sum) {
  constexpr int32_t kOne = 1 << 16;
  for (int i = 0; i < n; ++i) {
    const int32_t b = bgr[3 * i], g = bgr[3 * i + 1], r = bgr[3 * i + 2];
    const int32_t sum = b + g + r;
    mask[i] = static_cast<uint8_t>((sum >= min_sum) & (r * kOne >= r_lo * sum) &
                                   (g * kOne <= g_hi * sum) & (b * kOne <= b_hi * sum) &
                                   (r * kOne <= r_hi * sum) & (g * kOne >= g_lo * sum) &
                                   (b * kOne >= b_lo * sum));
  }
}

}  // namespace

void ColorDetector::classify(const uint8_t* bgr, int n, uint8_t* mask) const {
  auto c = [](int64_t v) { return static_cast<int32_t>(v); };  // all in [0, 65536]
  classify_row(bgr, n, mask, c(r_lo_), c(r_hi_), c(g_lo_), c(g_hi_), c(b_lo_), c(b_hi_),
               c(min_sum_));
}

}  // namespace sg::vision
