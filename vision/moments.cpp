#include "vision/moments.hpp"

#include <algorithm>
#include <cmath>

namespace sg::vision {

Blob blob_from_moments(const RawMoments& m) {
  Blob b;
  if (m.m00 <= 0) return b;
  const double m00 = static_cast<double>(m.m00);
  b.area = m00;                                                                       // eq. 12
  b.centroid = {static_cast<double>(m.m10) / m00, static_cast<double>(m.m01) / m00};  // eq. 11
  const double xc = b.centroid.x, yc = b.centroid.y;
  b.mu20 = static_cast<double>(m.m20) - xc * static_cast<double>(m.m10);  // eq. 13
  b.mu02 = static_cast<double>(m.m02) - yc * static_cast<double>(m.m01);  // eq. 14
  b.mu11 = static_cast<double>(m.m11) - yc * static_cast<double>(m.m10);  // eq. 15
  const double root = std::sqrt((b.mu20 - b.mu02) * (b.mu20 - b.mu02) + 4 * b.mu11 * b.mu11);
  b.major_axis = std::sqrt(std::max(0.0, 8 * (b.mu20 + b.mu02 + root) / m00));  // eq. 16
  b.minor_axis = std::sqrt(std::max(0.0, 8 * (b.mu20 + b.mu02 - root) / m00));  // eq. 17
  b.orientation = 0.5 * std::atan2(2 * b.mu11, b.mu20 - b.mu02);                // eq. 18
  const double c = std::cos(b.orientation), s = std::sin(b.orientation);
  const double l = b.major_axis / 2, w = b.minor_axis / 2;
  b.major_axis_ends = {cv::Point2d(xc + l * c, yc + l * s),   // eq. 19
                       cv::Point2d(xc - l * c, yc - l * s)};  // eq. 20
  b.minor_axis_ends = {cv::Point2d(xc + w * s, yc - w * c),   // eq. 21
                       cv::Point2d(xc - w * s, yc + w * c)};  // eq. 22
  double x0 = xc, x1 = xc, y0 = yc, y1 = yc;
  for (const auto& ends : {b.major_axis_ends, b.minor_axis_ends}) {
    for (const cv::Point2d& p : ends) {
      x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y),
      y1 = std::max(y1, p.y);
    }
  }
  b.bounding_box = {x0, y0, x1 - x0, y1 - y0};
  return b;
}

}  // namespace sg::vision
