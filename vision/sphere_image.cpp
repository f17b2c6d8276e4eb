#include "vision/sphere_image.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "vision/ball_fit.hpp"

namespace sg::vision {

namespace {

/// The ray bisecting the silhouette rays through c -+ a u (see the header).
Eigen::Vector3d bisector(const CameraModel& camera, const Eigen::Vector2d& c,
                         const Eigen::Vector2d& u, double a, double& alpha) {
  const Eigen::Vector3d d1 = camera.ray_camera(c - a * u), d2 = camera.ray_camera(c + a * u);
  alpha = std::acos(std::clamp(d1.dot(d2), -1.0, 1.0)) / 2;
  return (d1 + d2).normalized();
}

/// The sphere's silhouette in the image, `n` points evenly spaced around its cone; empty when
/// the camera is inside the sphere or any point is behind it.
std::vector<cv::Point2d> silhouette(const CameraModel& camera, const Eigen::Vector3d& centre,
                                    double radius, int n) {
  const Eigen::Vector3d to = centre - camera.centre();
  const double d = to.norm();
  if (!(d > radius * (1 + 1e-9))) return {};
  const Eigen::Vector3d a = to / d;
  const Eigen::Vector3d u = a.unitOrthogonal(), v = a.cross(u);
  const double sin_alpha = radius / d, cos_alpha = std::sqrt(1 - sin_alpha * sin_alpha);
  const double s = std::sqrt(d * d - radius * radius);
  std::vector<cv::Point2d> out;
  out.reserve(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double phi = 2 * M_PI * k / n;
    const Eigen::Vector3d ray = a * cos_alpha + (u * std::cos(phi) + v * std::sin(phi)) * sin_alpha;
    const auto px = camera.project(camera.centre() + s * ray);
    if (!px || !px->allFinite()) return {};
    out.emplace_back(px->x(), px->y());
  }
  return out;
}

/// The centroid of the area the closed polygon `outline` encloses (the region's eq. 11 centroid).
std::optional<Eigen::Vector2d> area_centroid(const std::vector<cv::Point2d>& outline) {
  double area2 = 0, cx = 0, cy = 0;
  for (size_t i = 0; i < outline.size(); ++i) {
    const cv::Point2d& p = outline[i];
    const cv::Point2d& q = outline[(i + 1) % outline.size()];
    const double cross = p.x * q.y - q.x * p.y;
    area2 += cross, cx += (p.x + q.x) * cross, cy += (p.y + q.y) * cross;
  }
  if (!(std::abs(area2) > 1e-9)) return std::nullopt;
  return Eigen::Vector2d(cx / (3 * area2), cy / (3 * area2));
}

/// The points of `outline` whose direction from `about` lies in a sector of `arc`.
std::vector<cv::Point2d> in_arc(const std::vector<cv::Point2d>& outline, cv::Point2d about,
                                uint64_t arc) {
  std::vector<cv::Point2d> out;
  for (const cv::Point2d& p : outline) {
    if (arc >> arc_sector(p.x - about.x, p.y - about.y) & 1) out.push_back(p);
  }
  return out;
}

}  // namespace

std::optional<Eigen::Vector2d> sphere_outline_centre(const CameraModel& camera,
                                                     const Eigen::Vector3d& centre, double radius,
                                                     uint64_t arc) {
  if (!(radius > 0) || !std::isfinite(radius) || !centre.allFinite()) return std::nullopt;
  const std::vector<cv::Point2d> outline = silhouette(camera, centre, radius, 720);
  if (outline.empty()) return std::nullopt;
  if (arc == kWholeArc) return area_centroid(outline);
  cv::Point2d about(0, 0);
  for (const cv::Point2d& p : outline) about += p / static_cast<double>(outline.size());
  BallFitter fitter(outline.size());
  for (int round = 0; round < 2; ++round) {
    const std::vector<cv::Point2d> part = in_arc(outline, about, arc);
    if (part.size() < 12) return std::nullopt;
    const BallFit f = fitter.fit(part, BallFitParams{});
    if (!f.ok) return std::nullopt;
    about = f.centre;
  }
  return Eigen::Vector2d(about.x, about.y);
}

Eigen::Vector2d sphere_centre_pixel(const CameraModel& camera, const Eigen::Vector2d& apparent,
                                    double radius_px) {
  if (!(radius_px > 0) || !std::isfinite(radius_px) || !apparent.allFinite()) return apparent;
  const Intrinsics& k = camera.intrinsics();
  const Eigen::Vector2d out = apparent - Eigen::Vector2d(k.cx, k.cy);
  const double n = out.norm();
  if (n < 1e-6) return apparent;
  const Eigen::Vector2d u = out / n;
  // The radius seen is sqrt(a b); a / b = cos(alpha) / sqrt(cos^2 theta - sin^2 alpha) follows
  // from the estimate, which moves it little: three rounds settle it.
  double a = radius_px, alpha = 0;
  Eigen::Vector3d d = bisector(camera, apparent, u, a, alpha);
  for (int round = 0; round < 3; ++round) {
    const double cos_theta = d.z(), sin_alpha = std::sin(alpha);
    const double q = cos_theta * cos_theta - sin_alpha * sin_alpha;
    if (!(q > 1e-9)) return apparent;
    a = radius_px * std::sqrt(std::cos(alpha) / std::sqrt(q));
    d = bisector(camera, apparent, u, a, alpha);
  }
  if (!(d.z() > 1e-9) || !d.allFinite()) return apparent;
  return camera.project_camera(d);
}

}  // namespace sg::vision
