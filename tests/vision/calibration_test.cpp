// Calibration (section 4) and triangulation (section 5.4): synthetic cameras of the paper's rig
// with known answers, degenerate input, robot-frame registration, and a real stereo checkerboard
// set against OpenCV's own calibration of it.

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <random>

#include "sim/stereo_rig.hpp"
#include "tests/support/workspace.hpp"
#include "vision/checkerboard.hpp"
#include "vision/dlt.hpp"
#include "vision/registration.hpp"
#include "vision/triangulation.hpp"

namespace sg::vision {
namespace {

using test::workspace_points;

std::vector<Correspondence> observe(const CameraModel& cam,
                                    const std::vector<Eigen::Vector3d>& world, double noise_px,
                                    unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<Correspondence> out;
  for (const auto& X : world) {
    out.push_back({X, *cam.project(X) + Eigen::Vector2d(noise(rng), noise(rng))});
  }
  return out;
}

Eigen::Matrix<double, 3, 4> unit(Eigen::Matrix<double, 3, 4> P) {
  P /= P.norm();
  return P(2, 3) < 0 ? Eigen::Matrix<double, 3, 4>(-P) : P;
}

// Noise-free correspondences recover P to 1e-9 (relative, up to scale), and K, R, t from it.
TEST(Dlt, NoiseFreeRecoversTheCamera) {
  const auto rig = sim::make_rig({});
  for (const CameraModel& truth : rig) {
    const DltResult r = calibrate_dlt(observe(truth, workspace_points(30, 1), 0.0, 2), 640, 480);
    EXPECT_LT((unit(r.P) - unit(truth.P())).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT(r.rms, 1e-9);
    EXPECT_TRUE(r.camera.K().isApprox(truth.K(), 1e-8));
    EXPECT_TRUE(r.camera.R().isApprox(truth.R(), 1e-9));
    EXPECT_LT((r.camera.centre() - truth.centre()).norm(), 1e-9);
  }
}

// With 0.3 px of noise: reprojection RMS <= 0.5 px, points triangulated across the workspace
// within 2 mm RMS; the refined estimate is never worse than the linear one in reprojection error
// (by construction, every seed) and is better in 3D error on average over the seeds.
TEST(Dlt, NoisyCorrespondencesGiveMillimetreTriangulation) {
  const auto rig = sim::make_rig({});
  double total_linear = 0, total_refined = 0;
  for (unsigned seed = 0; seed < 10; ++seed) {
    const auto calibration_points = workspace_points(40, 100 + seed);
    DltResult fitted[2];
    for (int c = 0; c < 2; ++c) {
      fitted[c] = calibrate_dlt(
          observe(rig[static_cast<size_t>(c)], calibration_points, 0.3, 7 * seed + c), 640, 480);
      EXPECT_LE(fitted[c].rms, 0.5) << seed;
      EXPECT_LE(fitted[c].rms, fitted[c].rms_linear + 1e-12) << "refined never worse";
    }
    double sum_linear = 0, sum_refined = 0;
    const auto test_points = workspace_points(200, 900 + seed);
    const auto left = observe(rig[0], test_points, 0.3, 11 + seed),
               right = observe(rig[1], test_points, 0.3, 13 + seed);
    const CameraModel lin[2] = {decompose_projection(fitted[0].P_linear, 640, 480),
                                decompose_projection(fitted[1].P_linear, 640, 480)};
    for (size_t i = 0; i < test_points.size(); ++i) {
      const auto refined =
          triangulate({&fitted[0].camera, &fitted[1].camera}, {left[i].pixel, right[i].pixel});
      const auto linear = triangulate({&lin[0], &lin[1]}, {left[i].pixel, right[i].pixel});
      sum_refined += (refined.position - test_points[i]).squaredNorm();
      sum_linear += (linear.position - test_points[i]).squaredNorm();
    }
    const double rms_refined = std::sqrt(sum_refined / 200),
                 rms_linear = std::sqrt(sum_linear / 200);
    EXPECT_LT(rms_refined, 0.002) << seed;
    total_linear += rms_linear;
    total_refined += rms_refined;
  }
  EXPECT_LT(total_refined, total_linear);
  std::printf("3D RMS, mean over 10 seeds: linear DLT %.3f mm, refined %.3f mm\n",
              total_linear * 100, total_refined * 100);
}

// Degenerate input is refused with a message that says which problem.
TEST(Dlt, DegenerateInputIsRefusedWithAReason) {
  const CameraModel cam = sim::make_rig({})[0];
  auto message = [&](std::vector<Correspondence> points) -> std::string {
    try {
      calibrate_dlt(points, 640, 480);
    } catch (const CalibrationInputError& e) {
      return e.what();
    }
    return "accepted";
  };
  auto points = observe(cam, workspace_points(12, 3), 0, 0);
  EXPECT_NE(message({points.begin(), points.begin() + 5}).find("at least 6 points, got 5"),
            std::string::npos);
  auto flat = points;
  for (auto& p : flat) p.world.z() = 0.1, p.pixel = *cam.project(p.world);
  EXPECT_NE(message(flat).find("one plane"), std::string::npos);
  auto twice = points;
  twice[7] = twice[2];
  EXPECT_NE(message(twice).find("points 3 and 8 are the same world point"), std::string::npos);
  auto nan = points;
  nan[4].pixel.x() = std::nan("");
  EXPECT_NE(message(nan).find("point 5 has a non-finite coordinate"), std::string::npos);
}

// Triangulation: exact without noise (also through lens distortion and with three views), the
// paper's linear form agrees, and the flags and sigma mean what they say.
TEST(Triangulation, ExactFlagsAndSigma) {
  sim::RigParams rp;
  rp.distortion = {-0.25, 0.08, 0.001, -0.001, 0};
  const auto rig = sim::make_rig(rp);
  const CameraModel third =
      CameraModel::look_at(640, 480, {}, {}, {0.45, -0.6, 0.5}, {0.45, 0, 0.1});
  for (const auto& X : workspace_points(50, 5)) {
    const Eigen::Vector2d l = *rig[0].project(X), r = *rig[1].project(X), t = *third.project(X);
    EXPECT_LT((triangulate({&rig[0], &rig[1]}, {l, r}).position - X).norm(), 1e-9);
    EXPECT_LT((triangulate({&rig[0], &rig[1], &third}, {l, r, t}).position - X).norm(), 1e-9);
    EXPECT_LT((triangulate_linear(rig[0], l, rig[1], r).position - X).norm(), 1e-7);
  }
  // Two cameras 2 mm apart looking at a point 0.5 m away: rays meet at 0.2 degrees.
  const CameraModel a = CameraModel::look_at(640, 480, {}, {}, {0.9, 0.0, 0.3}, {0.45, 0, 0.1});
  const CameraModel b = CameraModel::look_at(640, 480, {}, {}, {0.9, 0.002, 0.3}, {0.45, 0, 0.1});
  const Eigen::Vector3d X(0.45, 0.0, 0.1);
  EXPECT_TRUE(triangulate({&a, &b}, {*a.project(X), *b.project(X)}).near_parallel);
  EXPECT_FALSE(
      triangulate({&rig[0], &rig[1]}, {*rig[0].project(X), *rig[1].project(X)}).near_parallel);
  // sigma: the spread of 0.3 px-noise triangulations, within a factor 1.5.
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0, 0.3);
  Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero(), sigma;
  for (int k = 0; k < 400; ++k) {
    const auto t = triangulate({&rig[0], &rig[1]},
                               {*rig[0].project(X) + Eigen::Vector2d(noise(rng), noise(rng)),
                                *rig[1].project(X) + Eigen::Vector2d(noise(rng), noise(rng))});
    sum_sq += (t.position - X).cwiseAbs2();
    sigma = t.sigma;
  }
  const Eigen::Vector3d spread = (sum_sq / 400).cwiseSqrt();
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(sigma[i] / spread[i], 1 / 1.5) << i;
    EXPECT_LT(sigma[i] / spread[i], 1.5) << i;
  }
  EXPECT_THROW(triangulate({&rig[0]}, {Eigen::Vector2d(1, 1)}), std::invalid_argument);
}

// Registration recovers a rigid motion exactly; moving a calibration's world frame keeps every
// projection; too few or collinear points are refused.
TEST(Registration, RigidFitAndFrameChange) {
  const auto world = workspace_points(12, 21);
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  motion.translation() = Eigen::Vector3d(0.3, -1.2, 0.5);
  std::vector<Eigen::Vector3d> moved;
  for (const auto& p : world) moved.push_back(motion * p);
  const RigidFit fit = fit_rigid(world, moved);
  EXPECT_TRUE(fit.transform.isApprox(motion, 1e-12));
  EXPECT_LT(fit.rms, 1e-12);

  StereoCalibration in_camera;  // calibrated in the "moved" frame
  const auto rig = sim::make_rig({});
  in_camera.left = rig[0];
  in_camera.right = rig[1];
  const StereoCalibration in_robot = change_world_frame(in_camera, motion);
  for (const auto& p : world) {
    EXPECT_LT((*in_robot.left.project(p) - *in_camera.left.project(motion * p)).norm(), 1e-9);
    EXPECT_LT((*in_robot.right.project(p) - *in_camera.right.project(motion * p)).norm(), 1e-9);
  }
  EXPECT_THROW(fit_rigid({world.begin(), world.begin() + 3}, {moved.begin(), moved.begin() + 3}),
               CalibrationInputError);
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 6; ++i) line.emplace_back(0.1 * i, 0.2 * i, 0.0);
  EXPECT_THROW(fit_rigid(line, line), CalibrationInputError);
}

std::vector<std::string> fixture(const std::string& side) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(std::string(SG_SOURCE_DIR) +
                                                           "/tests/fixtures/stereo_checkerboard")) {
    if (e.path().filename().string().rfind(side, 0) == 0 && e.path().extension() == ".jpg")
      files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Real images with real lenses: RMS at most 0.5 px, and the baseline within 1% of what OpenCV's
// own stereo_calib sample found on the same images (tests/fixtures/stereo_checkerboard/README.md).
TEST(Checkerboard, RealStereoSetAgreesWithOpenCvsOwnCalibration) {
  const auto left = fixture("left"), right = fixture("right");
  ASSERT_EQ(left.size(), 13u);
  const CheckerboardResult r = calibrate_checkerboard(left, right, {{9, 6}, 0.025});
  EXPECT_LE(r.calibration.rms_left, 0.5);
  EXPECT_LE(r.calibration.rms_right, 0.5);
  EXPECT_LE(r.rms_stereo, 0.5);
  cv::FileStorage reference(
      std::string(SG_SOURCE_DIR) + "/tests/fixtures/stereo_checkerboard/reference_extrinsics.yml",
      cv::FileStorage::READ);
  cv::Mat T;
  reference["T"] >> T;
  const double baseline = (r.calibration.right.centre() - r.calibration.left.centre()).norm();
  EXPECT_NEAR(baseline / cv::norm(T), 1.0, 0.01);
  std::printf(
      "RMS left %.3f px, right %.3f px, stereo %.3f px; baseline %.2f mm (OpenCV's sample: %.2f "
      "mm)\n",
      r.calibration.rms_left, r.calibration.rms_right, r.rms_stereo, baseline * 1e3,
      cv::norm(T) * 1e3);
  int used = 0;
  for (const auto& v : r.views) used += v.used;
  EXPECT_EQ(used, 13);
}

// A wrong pattern, mismatched counts and unreadable images are refused with a reason.
TEST(Checkerboard, BadInputIsRefused) {
  const auto left = fixture("left"), right = fixture("right");
  try {
    calibrate_checkerboard(left, right, {{8, 5}, 0.025});
    FAIL();
  } catch (const CalibrationInputError& e) {
    EXPECT_NE(std::string(e.what()).find("8x5 board was found in 0 stereo pairs"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(calibrate_checkerboard(left, {right.begin(), right.end() - 1}, {}),
               CalibrationInputError);
  EXPECT_THROW(calibrate_checkerboard({"/nonexistent.png"}, {"/nonexistent.png"}, {}),
               CalibrationInputError);
}

}  // namespace
}  // namespace sg::vision
