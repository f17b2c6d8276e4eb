#include "vision/color_detector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace sg::vision {
namespace {

int64_t fixed(double v) { return std::llround(std::clamp(v, 0.0, 1.0) * 32768.0); }

/// ColorBounds's q for a bound X <= q S / 2^15 (0 <= q <= 2^15).
void set_bound(ColorBounds& k, int i, int64_t q) { k.q[i] = static_cast<uint16_t>(q); }

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
  const int64_t one = kOne;
  set_bound(bounds_, 0, r_hi_), set_bound(bounds_, 1, one - r_lo_);
  set_bound(bounds_, 2, g_hi_), set_bound(bounds_, 3, one - g_lo_);
  set_bound(bounds_, 4, b_hi_), set_bound(bounds_, 5, one - b_lo_);
  bounds_.min_sum = static_cast<int16_t>(std::min<int64_t>(min_sum_, 766));
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

}  // namespace sg::vision
