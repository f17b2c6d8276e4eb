// The image of a sphere: its centre's pixel from the ellipse's apparent centre and radius.

#include "vision/sphere_image.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace sg::vision {
namespace {

/// The two silhouette rays of a sphere (centre `c`, radius `r`, camera frame) in the plane of the
/// optical axis and the ray to `c`: the ray to c turned by +-asin(r / |c|) in that plane.
std::pair<Eigen::Vector3d, Eigen::Vector3d> silhouette_rays(const Eigen::Vector3d& c, double r) {
  const double alpha = std::asin(r / c.norm());
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ().cross(c).normalized();
  return {Eigen::AngleAxisd(alpha, axis) * c, Eigen::AngleAxisd(-alpha, axis) * c};
}

// Off the axis, the ellipse's centre is out from the sphere centre's pixel by a third of a pixel
// or more; from that centre and the radius of a disc of the image's area, the correction leaves
// under 0.02 px.
TEST(SphereImage, CentreOfTheEllipseGivesTheSpheresPixel) {
  const CameraModel cam = CameraModel::look_at(640, 480, {560, 560, 319.5, 239.5}, {},
                                               {0.8, -0.25, 0.4}, {0.45, 0, 0.1});
  for (const Eigen::Vector3d& world :
       {Eigen::Vector3d(0.45, 0.1, 0.12), Eigen::Vector3d(0.35, -0.15, 0.2),
        Eigen::Vector3d(0.55, 0.2, 0.0), Eigen::Vector3d(0.6, -0.2, 0.25)}) {
    const auto [a, b] = silhouette_rays(cam.to_camera(world), 0.035);
    const Eigen::Vector2d p1 = cam.project_camera(a), p2 = cam.project_camera(b);
    const Eigen::Vector2d ellipse_centre = (p1 + p2) / 2, truth = *cam.project(world);
    EXPECT_GT((ellipse_centre - truth).norm(), 0.3) << world.transpose();
    // The radius a region's area gives, sqrt(a b), from the projected silhouette's polygon.
    const Eigen::Vector3d c = cam.to_camera(world);
    double area = 0;
    Eigen::Vector2d last = cam.project_camera(a);
    for (int k = 1; k <= 720; ++k) {
      const Eigen::Vector2d p = cam.project_camera(Eigen::AngleAxisd(k * M_PI / 360, c.normalized()) * a);
      area += (last.x() * p.y() - p.x() * last.y()) / 2;
      last = p;
    }
    const double r = std::sqrt(std::abs(area) / M_PI);
    EXPECT_LT((sphere_centre_pixel(cam, ellipse_centre, r) - truth).norm(), 0.02)
        << world.transpose() << ": " << (ellipse_centre - truth).norm() << " px before";
  }
}

// On the principal point, or without a radius, the apparent centre is the answer.
TEST(SphereImage, NothingToCorrect) {
  const CameraModel cam = CameraModel::look_at(640, 480, {560, 560, 319.5, 239.5}, {},
                                               {0.8, -0.25, 0.4}, {0.45, 0, 0.1});
  EXPECT_EQ(sphere_centre_pixel(cam, {319.5, 239.5}, 20), Eigen::Vector2d(319.5, 239.5));
  EXPECT_EQ(sphere_centre_pixel(cam, {100, 50}, 0), Eigen::Vector2d(100, 50));
  EXPECT_EQ(sphere_centre_pixel(cam, {100, 50}, std::nan("")), Eigen::Vector2d(100, 50));
}

}  // namespace
}  // namespace sg::vision
