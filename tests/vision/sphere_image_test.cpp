// The image of a sphere: its centre's pixel from the ellipse's apparent centre and radius, and the
// centre a circle fit finds on part of its outline.

#include "vision/sphere_image.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "sim/camera_simulator.hpp"
#include "vision/ball_fit.hpp"
#include "vision/blob_tracker.hpp"
#include "vision/robot_calibration.hpp"

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
      const Eigen::Vector2d p =
          cam.project_camera(Eigen::AngleAxisd(k * M_PI / 360, c.normalized()) * a);
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

/// The camera of the tests above.
CameraModel test_camera() {
  return CameraModel::look_at(640, 480, {560, 560, 319.5, 239.5}, {}, {0.8, -0.25, 0.4},
                              {0.45, 0, 0.1});
}

// The whole outline's centre is the centre of the silhouette's conic, x^T (c c^T - cos^2(alpha)
// |c|^2 I) x = 0 in normalized coordinates (c the centre in the camera frame), solved in closed
// form: the centroid of the polygon through 720 of its points agrees within 0.01 px.
TEST(SphereOutline, WholeOutlineIsTheConicsCentre) {
  const CameraModel cam = test_camera();
  for (const Eigen::Vector3d& world :
       {Eigen::Vector3d(0.45, 0.1, 0.12), Eigen::Vector3d(0.35, -0.15, 0.2),
        Eigen::Vector3d(0.6, -0.2, 0.25)}) {
    const Eigen::Vector3d c = cam.to_camera(world);
    const double r = 0.035, cos2 = 1 - r * r / c.squaredNorm();
    const Eigen::Matrix3d m =
        c * c.transpose() - cos2 * c.squaredNorm() * Eigen::Matrix3d::Identity();
    const Eigen::Vector2d x0 = m.topLeftCorner<2, 2>().lu().solve(-m.block<2, 1>(0, 2));
    const Eigen::Vector2d truth = cam.project_camera({x0.x(), x0.y(), 1});
    const auto got = sphere_outline_centre(cam, world, r, kWholeArc);
    ASSERT_TRUE(got);
    EXPECT_LT((*got - truth).norm(), 0.01) << world.transpose();
    EXPECT_GT((truth - *cam.project(world)).norm(), 0.3) << "not a trivial case";
  }
}

// On the optical axis the image is a circle about the principal point: any part of its outline,
// half, a quarter or two opposite eighths, fits to that centre within 0.02 px.
TEST(SphereOutline, OnTheAxisEveryArcGivesThePrincipalPoint) {
  const CameraModel cam = test_camera();
  const Eigen::Vector3d on_axis = cam.centre() + 0.5 * cam.R().row(2).transpose();
  for (const uint64_t arc : {0xFFFFFFFF00000000ULL, 0x0000FFFF00000000ULL, 0x00FF000000FF0000ULL}) {
    const auto got = sphere_outline_centre(cam, on_axis, 0.035, arc);
    ASSERT_TRUE(got) << std::hex << arc;
    EXPECT_LT((*got - Eigen::Vector2d(319.5, 239.5)).norm(), 0.02) << std::hex << arc;
  }
}

// Nothing to model: no radius, the camera inside the ball, the ball behind it, no sector.
TEST(SphereOutline, RefusesWhatItCannotModel) {
  const CameraModel cam = test_camera();
  EXPECT_FALSE(sphere_outline_centre(cam, {0.45, 0, 0.1}, 0, kWholeArc));
  EXPECT_FALSE(sphere_outline_centre(cam, {0.45, 0, 0.1}, std::nan(""), kWholeArc));
  EXPECT_FALSE(sphere_outline_centre(cam, cam.centre(), 0.035, kWholeArc));
  EXPECT_FALSE(sphere_outline_centre(cam, 2 * cam.centre() - Eigen::Vector3d(0.45, 0, 0.1), 0.035,
                                     kWholeArc));
  EXPECT_FALSE(sphere_outline_centre(cam, {0.45, 0, 0.1}, 0.035, 0));
}

// The simulated gripper holds the ball near the right camera's edge of view (the calibration
// grid's stop 10), where it hides half the outline: the tracker's fitted centre is px from the
// projection of the ball's centre, and the model of that fit on the same sectors of the ball's
// exact image puts it within 0.4 px of where the tracker found it, in both cameras.
TEST(SphereOutline, ModelsTheTrackersFitOnTheRenderedBall) {
  sim::CameraSimulator sim{sim::SimParams{}};
  const CalibrationStop stop = RobotCalibration(RobotCalibrationParams{}).stops()[9];
  sim::ArmState arm;
  arm.present = arm.holding_object = true;
  arm.tool_position = stop.tool, arm.tool_rpy = stop.rpy, arm.gripper_opening = 0.07;
  std::array<BlobTracker, 2> trackers{BlobTracker({}, {640, 480}), BlobTracker({}, {640, 480})};
  std::array<Observation, 2> seen;
  sim::StereoFrame frame;
  for (int k = 0; k < 10; ++k) {
    sim.render(k, arm, frame);
    for (size_t c = 0; c < 2; ++c) seen[c] = trackers[c].track(frame.image[c]);
  }
  for (size_t c = 0; c < 2; ++c) {
    ASSERT_TRUE(seen[c].found) << c;
    ASSERT_NE(seen[c].arc, kWholeArc) << c << ": the gripper hides part of the ball";
    const Eigen::Vector2d found(seen[c].centre.x, seen[c].centre.y);
    const auto model = sphere_outline_centre(sim.camera(static_cast<int>(c)), frame.ball,
                                             sim.params().ball_radius, seen[c].arc);
    ASSERT_TRUE(model);
    const Eigen::Vector2d truth = *sim.camera(static_cast<int>(c)).project(frame.ball);
    EXPECT_GT((found - truth).norm(), 1.5) << c;
    EXPECT_LT((found - *model).norm(), 0.4) << c;
    std::printf(
        "camera %zu: support %.2f, fit %.2f px from the centre's pixel, %.2f px from the "
        "model's\n",
        c, seen[c].fit_support, (found - truth).norm(), (found - *model).norm());
  }
}

}  // namespace
}  // namespace sg::vision
