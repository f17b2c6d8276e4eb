// sg-calibrate as a process: DLT from CSV files, the real checkerboard set, registration to the
// robot frame, and bad input that leaves a good file as it was.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <random>
#include <sstream>

#include "sim/stereo_rig.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/workspace.hpp"
#include "vision/calibration_file.hpp"
#include "vision/registration.hpp"
#include "vision/triangulation.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

// DLT from two CSV files of the simulated rig's points (0.3 px noise): a calibration file whose
// cameras triangulate new points across the workspace within 2 mm RMS.
TEST(Calibrate, DltFromCsv) {
  const std::string dir = make_temp_dir();
  const auto rig = sim::make_rig({});
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0, 0.3);
  for (int c = 0; c < 2; ++c) {
    std::ofstream csv(dir + (c == 0 ? "/left.csv" : "/right.csv"));
    csv << "X,Y,Z,u,v\n# points carried by the arm\n" << std::setprecision(17);
    for (const auto& p : workspace_points(30, 8)) {
      const Eigen::Vector2d px = *rig[static_cast<size_t>(c)].project(p);
      csv << p.x() << "," << p.y() << "," << p.z() << "," << px.x() + noise(rng) << ","
          << px.y() + noise(rng) << "\n";
    }
  }
  const ProcessResult r = run({program("sg-calibrate"), "dlt", "--left", dir + "/left.csv",
                               "--right", dir + "/right.csv", "--out", dir + "/cams.yaml"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("left camera: 30 points, RMS reprojection error 0."), std::string::npos)
      << r.out;
  const auto c = vision::read_calibration(dir + "/cams.yaml");
  double sum = 0;
  const auto test_points = workspace_points(50, 77);
  for (const auto& p : test_points) {
    const auto t =
        vision::triangulate({&c.left, &c.right}, {*rig[0].project(p), *rig[1].project(p)});
    sum += (t.position - p).squaredNorm();
  }
  EXPECT_LT(std::sqrt(sum / test_points.size()), 0.002);
}

// The real stereo set: 13 views used, the baseline OpenCV's sample found, a readable file.
TEST(Calibrate, CheckerboardOnRealImages) {
  const std::string dir = make_temp_dir();
  for (const char* side : {"left", "right"}) {
    fs::create_directory(dir + "/" + side);
    for (const auto& e : fs::directory_iterator(std::string(SG_SOURCE_DIR) +
                                                "/tests/fixtures/stereo_checkerboard")) {
      if (e.path().filename().string().rfind(side, 0) == 0)
        fs::copy(e.path(), dir + "/" + side + "/" + e.path().filename().string());
    }
  }
  const ProcessResult r =
      run({program("sg-calibrate"), "checkerboard", "--left", dir + "/left", "--right",
           dir + "/right", "--pattern", "9x6", "--square", "0.025", "--out", dir + "/cams.yaml"},
          120s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int used = 0;
  for (size_t at = r.out.find(" yes "); at != std::string::npos; at = r.out.find(" yes ", at + 1))
    ++used;
  EXPECT_EQ(used, 13) << r.out;
  EXPECT_NE(r.err.find("finding the board in left01.jpg (1 of 26)"), std::string::npos)
      << "progress";
  const auto c = vision::read_calibration(dir + "/cams.yaml");
  EXPECT_NEAR((c.right.centre() - c.left.centre()).norm(), 0.08358, 0.0008);
}

// Registration: a calibration in another frame, plus points known in the robot frame, gives the
// robot-frame calibration back.
TEST(Calibrate, RegisterMovesTheCalibrationIntoTheRobotFrame) {
  const std::string dir = make_temp_dir();
  const auto rig = sim::make_rig({});
  vision::StereoCalibration robot_frame;
  robot_frame.left = rig[0];
  robot_frame.right = rig[1];
  Eigen::Isometry3d robot_from_camera = Eigen::Isometry3d::Identity();  // any frame will do
  robot_from_camera.linear() =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, -1, 0.4).normalized()).toRotationMatrix();
  robot_from_camera.translation() = Eigen::Vector3d(0.5, 0.1, -0.3);
  vision::write_calibration(dir + "/camera_frame.yaml",
                            vision::change_world_frame(robot_frame, robot_from_camera));
  std::ofstream csv(dir + "/marks.csv");
  csv << std::setprecision(17);
  for (const auto& p : workspace_points(8, 3)) {
    const Eigen::Vector2d l = *rig[0].project(p), r = *rig[1].project(p);
    csv << p.x() << "," << p.y() << "," << p.z() << "," << l.x() << "," << l.y() << "," << r.x()
        << "," << r.y() << "\n";
  }
  csv.close();
  const ProcessResult r =
      run({program("sg-calibrate"), "register", "--calibration", dir + "/camera_frame.yaml",
           "--points", dir + "/marks.csv", "--out", dir + "/robot.yaml"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto back = vision::read_calibration(dir + "/robot.yaml");
  for (const auto& p : workspace_points(20, 90)) {
    EXPECT_LT((*back.left.project(p) - *rig[0].project(p)).norm(), 1e-6);
    EXPECT_LT((*back.right.project(p) - *rig[1].project(p)).norm(), 1e-6);
  }
}

// Bad input: one line naming the file and line or the problem; an existing file stays as it was.
TEST(Calibrate, BadInputLeavesTheGoodFile) {
  const std::string dir = make_temp_dir();
  const std::string good = dir + "/cams.yaml";
  const auto rig = sim::make_rig({});
  vision::StereoCalibration c;
  c.left = rig[0];
  c.right = rig[1];
  vision::write_calibration(good, c);
  const std::string before = read_text(good);
  std::ofstream(dir + "/bad.csv") << "X,Y,Z,u,v\n0.1,0.2,0.3,10,20\n0.1,abc,0.3,10,20\n";
  std::ofstream flat(dir + "/flat.csv");
  for (int i = 0; i < 10; ++i)
    flat << 0.1 * i << "," << 0.05 * (i % 3) << ",0.1," << 10 * i << "," << 7 * i << "\n";
  flat.close();
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"dlt", "--left", dir + "/bad.csv", "--right", dir + "/bad.csv"},
       "bad.csv:3: 'abc' is not a number"},
      {{"dlt", "--left", dir + "/flat.csv", "--right", dir + "/flat.csv"}, "one plane"},
      {{"dlt", "--left", dir + "/none.csv", "--right", dir + "/none.csv"}, "none.csv: cannot open"},
      {{"checkerboard", "--left", dir, "--right", dir, "--pattern", "nine"},
       "expected inner corners"},
      {{"checkerboard", "--left", "/nonexistent", "--right", dir}, "not a folder"},
  };
  for (const auto& [args, needle] : cases) {
    std::vector<std::string> argv = {program("sg-calibrate")};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"--out", good});
    const ProcessResult r = run(argv, 60s);
    EXPECT_EQ(r.exit_code, 1) << needle;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    EXPECT_EQ(read_text(good), before) << "the good file is untouched";
  }
}

}  // namespace
}  // namespace sg::test

#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "vision/triangulation.hpp"

namespace sg::test {
namespace {

// sg-calibrate robot over LCM. The test plays the arm (ARM_STATUS after each ARM_COMMAND) and the
// vision stage (BLOB_LEFT/RIGHT of the carried ball, projected by the true cameras): the written
// calibration triangulates the workspace within 2 mm in the robot frame.
TEST(Calibrate, RobotGuidedOverLcm) {
  constexpr int kPort = 7913;
  ASSERT_TRUE(multicast_available(kPort));
  const std::string dir = make_temp_dir();
  const auto rig = sim::make_rig({});
  Bus bus(test_url(kPort));  // the arm's driver: ARM_STATUS, and the commands it hears
  bus.set_guard(vouching_as("sg-arm-driver"));
  Bus eyes(test_url(kPort));  // sg-vision: the blobs of the carried ball
  eyes.set_guard(vouching_as("sg-vision"));
  Eigen::Vector3d ball = Eigen::Vector3d::Zero();
  int64_t executed = -1, commands = 0, releases = 0;
  bool moving = false;
  auto arrive_at = std::chrono::steady_clock::now();
  bus.subscribe<stereograsp::arm_cmd_t>("ARM_COMMAND", [&](const auto& c, const auto&) {
    // The commander's lease messages move nothing (docs/arm.md): heartbeats while it waits, one
    // release at the end.
    if (c.mode == stereograsp::arm_cmd_t::MODE_HEARTBEAT) return;
    if (c.mode == stereograsp::arm_cmd_t::MODE_RELEASE) {
      ++releases;
      return;
    }
    ball = {c.position[0], c.position[1], c.position[2]};
    executed = c.sequence;
    moving = true;
    ++commands;
    arrive_at = std::chrono::steady_clock::now() + 50ms;
  });
  Child calibrate({program("sg-calibrate"), "robot", "--out", dir + "/robot.yaml", "--settle",
                   "0.05", "--frames-per-stop", "5", "--timeout", "10", "--lcm-url",
                   test_url(kPort)});
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0, 0.2);
  const auto deadline = std::chrono::steady_clock::now() + 90s;
  while (calibrate.running() && std::chrono::steady_clock::now() < deadline) {
    bus.handle(5ms);
    if (moving && std::chrono::steady_clock::now() >= arrive_at) moving = false;
    stereograsp::arm_status_t s{};
    s.utime = now_utime();
    s.state =
        moving ? stereograsp::arm_status_t::STATE_MOVING : stereograsp::arm_status_t::STATE_IDLE;
    s.last_executed_sequence = moving ? executed - 1 : executed;
    bus.publish("ARM_STATUS", s);
    for (int c = 0; c < 2 && executed >= 0; ++c) {
      stereograsp::blob_t b{};
      b.utime = now_utime();
      b.camera = static_cast<int8_t>(c);
      b.found = 1;
      const Eigen::Vector2d px = *rig[static_cast<size_t>(c)].project(ball);
      b.centroid[0] = px.x() + noise(rng), b.centroid[1] = px.y() + noise(rng);
      b.centre[0] = b.centroid[0], b.centre[1] = b.centroid[1];  // a whole disc: no fit
      b.fit_support = std::nan("");
      eyes.publish(c == 0 ? "BLOB_LEFT" : "BLOB_RIGHT", b);
    }
  }
  const ProcessResult r = calibrate.wait(5s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("18 stops (0 skipped"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("stop 18 of 18: collecting"), std::string::npos) << "progress lines";
  EXPECT_EQ(commands, 18);
  EXPECT_EQ(releases, 1) << "sg-calibrate robot gives the arm back when done";
  const auto c = vision::read_calibration(dir + "/robot.yaml");
  double sum = 0;
  const auto points = workspace_points(50, 31);
  for (const auto& p : points) {
    sum += (vision::triangulate({&c.left, &c.right}, {*rig[0].project(p), *rig[1].project(p)})
                .position -
            p)
               .squaredNorm();
  }
  EXPECT_LT(std::sqrt(sum / static_cast<double>(points.size())), 0.002);
}

}  // namespace
}  // namespace sg::test
