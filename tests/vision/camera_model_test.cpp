// The camera model against OpenCV's own projection, and its inverse operations.

#include "vision/camera_model.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>

namespace sg::vision {
namespace {

CameraModel distorted_camera() {
  return CameraModel::look_at(640, 480, {530.0, 525.0, 322.0, 241.0},
                              {-0.28, 0.11, 0.0012, -0.0008, -0.02}, {0.8, -0.25, 0.4},
                              {0.45, 0.0, 0.1});
}

// project() agrees with cv::projectPoints, distortion included, to 1e-9 px.
TEST(CameraModel, ProjectionMatchesOpenCv) {
  const CameraModel cam = distorted_camera();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  std::vector<cv::Point3d> world;
  for (int i = 0; i < 200; ++i) world.emplace_back(0.45 + u(rng), u(rng), 0.1 + u(rng) / 2);
  cv::Mat R, t, K;
  cv::eigen2cv(cam.R(), R);
  cv::eigen2cv(cam.t(), t);
  cv::eigen2cv(cam.K(), K);
  cv::Mat rvec;
  cv::Rodrigues(R, rvec);
  const Distortion& d = cam.distortion();
  std::vector<cv::Point2d> expected;
  cv::projectPoints(world, rvec, t, K, std::vector<double>{d.k1, d.k2, d.p1, d.p2, d.k3}, expected);
  for (size_t i = 0; i < world.size(); ++i) {
    const auto px = cam.project({world[i].x, world[i].y, world[i].z});
    ASSERT_TRUE(px.has_value());
    EXPECT_NEAR(px->x(), expected[i].x, 1e-9);
    EXPECT_NEAR(px->y(), expected[i].y, 1e-9);
  }
}

// Without distortion, project() is the paper's P = K[R|t] followed by division (eq. 1-4).
TEST(CameraModel, UndistortedProjectionIsPTimesW) {
  const CameraModel cam = CameraModel::look_at(640, 480, {}, {}, {0.8, 0.25, 0.4}, {0.45, 0, 0.1});
  const Eigen::Vector3d X(0.5, -0.1, 0.05);
  const Eigen::Vector3d w = cam.P() * X.homogeneous();
  const Eigen::Vector2d px = *cam.project(X);
  EXPECT_NEAR(px.x(), w.x() / w.z(), 1e-9);
  EXPECT_NEAR(px.y(), w.y() / w.z(), 1e-9);
}

// The ray through a point's pixel points at the point; undistort inverts distort.
TEST(CameraModel, RayThroughPixelRoundTrip) {
  const CameraModel cam = distorted_camera();
  for (const Eigen::Vector3d& X : {Eigen::Vector3d(0.45, 0, 0.1), Eigen::Vector3d(0.3, 0.2, 0.0),
                                   Eigen::Vector3d(0.6, -0.2, 0.2)}) {
    const Eigen::Vector3d ray = cam.ray_camera(*cam.project(X));
    EXPECT_NEAR(ray.dot(cam.to_camera(X).normalized()), 1.0, 1e-12);
  }
  const Eigen::Vector2d n(0.31, -0.22);
  EXPECT_NEAR((cam.undistort(cam.distort(n)) - n).norm(), 0.0, 1e-12);
}

// look_at puts the target on the principal point and the camera where asked; behind is nullopt.
TEST(CameraModel, LookAtAndBehind) {
  const Eigen::Vector3d eye(0.8, -0.25, 0.4), target(0.45, 0, 0.1);
  const CameraModel cam = CameraModel::look_at(640, 480, {560, 560, 319.5, 239.5}, {}, eye, target);
  const Eigen::Vector2d px = *cam.project(target);
  EXPECT_NEAR(px.x(), 319.5, 1e-9);
  EXPECT_NEAR(px.y(), 239.5, 1e-9);
  EXPECT_NEAR((cam.centre() - eye).norm(), 0.0, 1e-12);
  EXPECT_FALSE(cam.project(eye + (eye - target)).has_value());
  // Image "up" is world up: a point above the target projects above it (smaller v).
  EXPECT_LT(cam.project(target + Eigen::Vector3d(0, 0, 0.05))->y(), px.y());
}

// Nonsense intrinsics are refused.
TEST(CameraModel, RejectsBadIntrinsics) {
  EXPECT_THROW(CameraModel(640, 480, {0, 500, 320, 240}, {}, Eigen::Matrix3d::Identity(),
                           Eigen::Vector3d::Zero()),
               std::invalid_argument);
  EXPECT_THROW(CameraModel(0, 480, {}, {}, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()),
               std::invalid_argument);
}

}  // namespace
}  // namespace sg::vision
