// The renderer: the ball's image against the analytic projection of a sphere, the paper's rig,
// determinism.

#include <gtest/gtest.h>

#include "sim/camera_simulator.hpp"

namespace sg::sim {
namespace {

struct Ellipse {
  Eigen::Vector2d centre;
  double area;
};

/// The image of a sphere is the conic of the cone of rays tangent to it: for normalized image
/// points x, (x . X0)^2 = |x|^2 (|X0|^2 - r^2), X0 the centre in the camera frame. In pixels
/// C = K^-T Q K^-1 with Q = X0 X0^T - (|X0|^2 - r^2) I. Centre and area follow from C.
Ellipse sphere_image(const vision::CameraModel& cam, const Eigen::Vector3d& centre, double r) {
  const Eigen::Vector3d X0 = cam.to_camera(centre);
  const Eigen::Matrix3d Q =
      X0 * X0.transpose() - (X0.squaredNorm() - r * r) * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Kinv = cam.K().inverse();
  Eigen::Matrix3d C = Kinv.transpose() * Q * Kinv;
  Eigen::Matrix2d M = C.topLeftCorner<2, 2>();
  if (M.determinant() < 0 || M(0, 0) < 0) C = -C, M = -M;  // make M positive definite
  const Eigen::Vector2d b = C.topRightCorner<2, 1>();
  const Eigen::Vector2d c = -M.inverse() * b;
  const double f = C(2, 2) - b.dot(M.inverse() * b);
  return {c, M_PI * std::abs(f) / std::sqrt(M.determinant())};
}

Ellipse moments(const cv::Mat& coverage) {
  double m00 = 0, m10 = 0, m01 = 0;
  for (int y = 0; y < coverage.rows; ++y) {
    for (int x = 0; x < coverage.cols; ++x) {
      const double w = coverage.at<float>(y, x);
      m00 += w, m10 += w * x, m01 += w * y;
    }
  }
  return {{m10 / m00, m01 / m00}, m00};
}

SimParams quiet() {
  SimParams p;
  p.noise_sigma = 0;
  p.lighting.gain_amplitude = 0;
  p.lighting.colour_amplitude = 0;
  return p;
}

// The rendered ball's centroid is the analytic ellipse's centre within 0.1 px and its area is the
// ellipse's within 2%, on the axis and far off it where perspective moves the centre.
TEST(Renderer, BallSilhouetteMatchesTheAnalyticEllipse) {
  CameraSimulator sim(quiet());
  double most_off_axis = 0;  // px between the ellipse's centre and the projected ball centre
  double worst_centre = 0, worst_area = 0;
  for (int cam = 0; cam < 2; ++cam) {
    for (const Eigen::Vector3d& p :  // within the paper's motion: on the axis and far from it
         {Eigen::Vector3d(0.45, 0.0, 0.10), Eigen::Vector3d(0.30, 0.25, 0.10),
          Eigen::Vector3d(0.60, -0.10, 0.10), Eigen::Vector3d(0.45, -0.25, 0.10),
          Eigen::Vector3d(0.40, 0.1, 0.25)}) {
      const Ellipse truth = sphere_image(sim.camera(cam), p, 0.035);
      most_off_axis = std::max(most_off_axis, (truth.centre - *sim.camera(cam).project(p)).norm());
      const Ellipse rendered = moments(sim.renderer(cam).ball_coverage(p, 0.035));
      EXPECT_LT((rendered.centre - truth.centre).norm(), 0.1)
          << "camera " << cam << " at " << p.transpose();
      EXPECT_NEAR(rendered.area / truth.area, 1.0, 0.02) << "camera " << cam;
      worst_centre = std::max(worst_centre, (rendered.centre - truth.centre).norm());
      worst_area = std::max(worst_area, std::abs(rendered.area / truth.area - 1.0));
    }
  }
  // Off the axis the ellipse's centre is not where the ball's centre projects, by more than the
  // tolerance: the check above would notice a renderer that drew a disc around the projection.
  EXPECT_GT(most_off_axis, 0.3);
  std::printf("worst centroid error %.4f px, worst area error %.3f%%, perspective offset %.2f px\n",
              worst_centre, 100 * worst_area, most_off_axis);
}

// The rig is the paper's: cameras 0.50 m apart, each turned 30 degrees in, axes meeting on target.
TEST(Renderer, RigIsThePapers) {
  const RigParams rig;
  const auto cams = make_rig(rig);
  EXPECT_NEAR((cams[0].centre() - cams[1].centre()).norm(), 0.50, 1e-12);
  const Eigen::Vector3d mid = (cams[0].centre() + cams[1].centre()) / 2;
  const Eigen::Vector3d forward = (rig.target - mid).normalized();
  for (const auto& cam : cams) {
    const Eigen::Vector3d axis = cam.R().row(2).transpose();
    EXPECT_NEAR(std::acos(axis.dot(forward)) * 180 / M_PI, 30.0, 1e-9);
    EXPECT_NEAR((*cam.project(rig.target) - Eigen::Vector2d(319.5, 239.5)).norm(), 0.0, 1e-9);
  }
  EXPECT_LT(cams[0].centre().y(), cams[1].centre().y()) << "left is left, seen from behind the rig";
}

// Over two minutes of the paper's motion the whole ball stays inside both images.
TEST(Renderer, PapersMotionStaysInView) {
  const auto cams = make_rig(RigParams{});
  ScenarioParams sp;
  sp.phase = 0;
  const auto scenario = make_scenario(sp);
  for (double t = 0; t < 120; t += 0.25) {
    const Eigen::Vector3d p = scenario->position(t);
    for (const auto& cam : cams) {
      const Ellipse e = sphere_image(cam, p, 0.035);
      const double r = std::sqrt(e.area / M_PI) * 1.5;
      EXPECT_GT(e.centre.x() - r, 0) << t;
      EXPECT_LT(e.centre.x() + r, 640) << t;
      EXPECT_GT(e.centre.y() - r, 0) << t;
      EXPECT_LT(e.centre.y() + r, 480) << t;
    }
  }
}

// The same seed gives the same bytes; another seed gives other noise and distractors.
TEST(Renderer, SameSeedSameBytes) {
  SimParams p;
  p.occlusion.episodes = {{1.0, 1.0}};
  CameraSimulator a(p), b(p);
  p.scenario.seed = p.scene.seed = 2;
  CameraSimulator c(p);
  StereoFrame fa, fb, fc;
  for (int64_t k : {0, 37, 45}) {
    a.render(k, {}, fa);
    b.render(k, {}, fb);
    c.render(k, {}, fc);
    for (int i = 0; i < 2; ++i) {
      EXPECT_EQ(cv::norm(fa.image[i], fb.image[i], cv::NORM_INF), 0.0) << k;
      EXPECT_GT(cv::norm(fa.image[i], fc.image[i], cv::NORM_L1), 0.0) << k;
    }
  }
}

// A gripper between a camera and the ball hides it from that camera.
TEST(Renderer, GripperHidesTheBall) {
  CameraSimulator sim(quiet());
  StereoFrame frame;
  sim.render(0, {}, frame);
  // The gripper points from the left camera at the ball, its palm toward the camera.
  const Eigen::Vector3d approach = (frame.ball - sim.camera(0).centre()).normalized();
  ArmState arm;
  arm.present = true;
  arm.tool_rpy = {0, std::acos(approach.z()), std::atan2(approach.y(), approach.x())};
  arm.tool_position = frame.ball + 0.2 * (sim.camera(0).centre() - frame.ball);
  StereoFrame hidden;
  sim.render(0, arm, hidden);
  EXPECT_LT(hidden.visibility[0].visible_px, 0.5 * frame.visibility[0].visible_px);
  EXPECT_GT(frame.visibility[0].visible_px, 1000.0);
}

}  // namespace
}  // namespace sg::sim

namespace sg::sim {
namespace {

// Motion blur smears a moving ball and leaves a still one as it was.
TEST(Renderer, MotionBlurSmearsOnlyWhatMoves) {
  SimParams sharp = quiet();
  sharp.scenario.rpm = 20;  // fast enough to smear within 0.1 s
  SimParams blurred = sharp;
  blurred.exposure = 0.1;
  blurred.motion_blur_samples = 6;
  CameraSimulator a(sharp), b(blurred);
  StereoFrame fa, fb;
  a.render(5, {}, fa);
  b.render(5, {}, fb);
  EXPECT_GT(cv::norm(fa.image[0], fb.image[0], cv::NORM_L1), 2000.0);
  EXPECT_NEAR(fb.visibility[0].silhouette_px / fa.visibility[0].silhouette_px, 1.0, 0.02)
      << "blur spreads the ball's light, it does not add any";
  sharp.scenario.kind = blurred.scenario.kind = "still";
  CameraSimulator c(sharp), d(blurred);
  c.render(5, {}, fa);
  d.render(5, {}, fb);
  EXPECT_LE(cv::norm(fa.image[0], fb.image[0], cv::NORM_INF), 1.0);
}

}  // namespace
}  // namespace sg::sim
