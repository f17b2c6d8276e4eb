// sg-camera-sim as a process: frames and truth on the bus, videos and CSV on disk, bad input.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <thread>

#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/wait.hpp"
#include "vision/calibration_file.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;

// 12 stereo frames at 4 Hz arrive as JPEG CAMERA_LEFT/RIGHT and GROUND_TRUTH, with the same
// capture times 0.25 s apart, decodable, and the truth seen by both cameras.
TEST(CameraSim, PublishesFramesAndTruthOnTheBus) {
  constexpr int kPort = 7906;
  ASSERT_TRUE(multicast_available(kPort));
  Bus bus(test_url(kPort));
  std::vector<stereograsp::image_t> left, right;
  std::vector<stereograsp::point3_t> truth;
  bus.subscribe<stereograsp::image_t>("CAMERA_LEFT",
                                      [&](const auto& m, const auto&) { left.push_back(m); });
  bus.subscribe<stereograsp::image_t>("CAMERA_RIGHT",
                                      [&](const auto& m, const auto&) { right.push_back(m); });
  bus.subscribe<stereograsp::point3_t>("GROUND_TRUTH",
                                       [&](const auto& m, const auto&) { truth.push_back(m); });
  Child sim({program("sg-camera-sim"), "--rate", "4", "--fast", "--frames", "12", "--lcm-url",
             test_url(kPort)});
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (truth.size() < 12 && std::chrono::steady_clock::now() < deadline) bus.handle(100ms);
  while (bus.handle(200ms)) {
  }
  const ProcessResult done = sim.wait(30s);
  EXPECT_EQ(done.exit_code, 0) << done.err;
  ASSERT_EQ(left.size(), 12u);
  ASSERT_EQ(right.size(), 12u);
  ASSERT_EQ(truth.size(), 12u);
  for (size_t k = 0; k < 12; ++k) {
    EXPECT_EQ(left[k].utime, truth[k].utime);
    EXPECT_EQ(right[k].utime, truth[k].utime);
    EXPECT_EQ(left[k].frame_number, static_cast<int64_t>(k));
    if (k > 0) {
      EXPECT_EQ(truth[k].utime - truth[k - 1].utime, 250000);
    }
    EXPECT_EQ(left[k].pixel_format, stereograsp::image_t::FORMAT_JPEG);
    EXPECT_EQ(truth[k].seen_by,
              stereograsp::point3_t::SEEN_LEFT | stereograsp::point3_t::SEEN_RIGHT);
  }
  const cv::Mat decoded = cv::imdecode(left[3].data, cv::IMREAD_COLOR);
  EXPECT_EQ(decoded.cols, 640);
  EXPECT_EQ(decoded.rows, 480);
}

// Asked for more frames a second than it can render (1000 Hz), the simulator drops the late ones
// as a camera would: the frames it publishes are on the 1 ms timeline, each stamped with its own
// slot, none far behind the clock, and published plus dropped is the whole timeline.
TEST(CameraSim, DropsFramesItCannotRenderInTime) {
  constexpr int kPort = 7977;
  ASSERT_TRUE(multicast_available(kPort));
  Bus bus(test_url(kPort));
  std::vector<std::pair<stereograsp::image_t, int64_t>> left;  // with the receive time
  bus.subscribe<stereograsp::image_t>("CAMERA_LEFT", [&](const auto& m, const ReceiveInfo& info) {
    left.emplace_back(m, info.recv_utime);
  });
  const int64_t started = now_utime();
  Child sim({program("sg-camera-sim"), "--rate", "1000", "--frames", "300", "--max-lag", "0.005",
             "--lcm-url", test_url(kPort)});
  ASSERT_TRUE(eventually(
      bus, [&] { return !sim.running(); }, 60s, "sg-camera-sim to end its 0.3 s timeline"));
  while (bus.handle(200ms)) {
  }
  const ProcessResult done = sim.wait(10s);
  ASSERT_EQ(done.exit_code, 0) << done.err;
  long long published = -1, dropped = -1;
  const size_t at = done.out.find("published ");
  ASSERT_NE(at, std::string::npos) << done.out;
  ASSERT_EQ(std::sscanf(done.out.c_str() + at,
                        "published %lld stereo frames in %*f s (%*f per "
                        "second), dropped %lld late",
                        &published, &dropped),
            2)
      << done.out;
  EXPECT_GT(dropped, 0) << done.out;
  EXPECT_EQ(published + dropped, 300) << done.out;
  ASSERT_GT(left.size(), 1u);
  EXPECT_LE(static_cast<long long>(left.size()), published);
  for (size_t k = 1; k < left.size(); ++k) {
    const auto& [m, recv] = left[k];
    EXPECT_GT(m.frame_number, left[k - 1].first.frame_number);
    EXPECT_EQ(m.utime - left[0].first.utime, (m.frame_number - left[0].first.frame_number) * 1000);
    // Rendering every frame, the last would be published about 300 renders - 0.3 s late (0.9 s
    // in Release, 6 s under sanitizers); dropping, at most max_lag + one render.
    EXPECT_LT(recv - m.utime, 250'000) << "frame " << m.frame_number << " published late";
  }
  EXPECT_GT(left.front().first.utime, started);
}

/// sg-camera-sim at 10 Hz for 40 frames while `bus` publishes a simulated arm holding the ball at
/// (0.40, 0.10, 0.30); the GROUND_TRUTH it published.
std::vector<stereograsp::point3_t> truth_while_holding(Bus& bus, int port) {
  std::vector<stereograsp::point3_t> truth;
  Bus watcher(test_url(port));
  watcher.subscribe<stereograsp::point3_t>("GROUND_TRUTH",
                                           [&](const auto& m, const auto&) { truth.push_back(m); });
  Child sim(
      {program("sg-camera-sim"), "--rate", "10", "--frames", "40", "--lcm-url", test_url(port)});
  stereograsp::sim_arm_state_t arm{};
  arm.tool_position[0] = 0.40, arm.tool_position[1] = 0.10, arm.tool_position[2] = 0.30;
  arm.tool_orientation[1] = M_PI;
  arm.gripper_opening = 0.06;
  arm.holding_object = 1;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (truth.size() < 40 && std::chrono::steady_clock::now() < deadline) {
    bus.publish("SIM_ARM_STATE", arm);
    watcher.handle(50ms);
  }
  EXPECT_EQ(sim.wait(30s).exit_code, 0);
  return truth;
}

// The gripper's state on SIM_ARM_STATE, vouched for by sg-c550-sim, reaches the simulator: a
// ball held by the gripper is where the tool is, in GROUND_TRUTH.
TEST(CameraSim, FollowsSimArmStateFromTheBus) {
  constexpr int kPort = 7908;
  ASSERT_TRUE(multicast_available(kPort));
  Bus c550(test_url(kPort));
  c550.set_guard(vouching_as("sg-c550-sim"));
  const std::vector<stereograsp::point3_t> truth = truth_while_holding(c550, kPort);
  ASSERT_GE(truth.size(), 30u);
  const stereograsp::point3_t& last = truth.back();
  EXPECT_DOUBLE_EQ(last.position[0], 0.40);
  EXPECT_DOUBLE_EQ(last.position[1], 0.10);
  EXPECT_DOUBLE_EQ(last.position[2], 0.30);
}

// A SIM_ARM_STATE nobody the lab allows vouched for (a host without credentials, or one holding
// only sg-vision's) cannot carry the simulated ball away: it stays on its path, never at the tool.
TEST(CameraSim, IgnoresSimArmStateNobodyVouchedFor) {
  constexpr int kPort = 7909;
  ASSERT_TRUE(multicast_available(kPort));
  for (const bool as_vision : {false, true}) {
    Bus rogue(test_url(kPort));
    if (as_vision) rogue.set_guard(vouching_as("sg-vision"));
    const std::vector<stereograsp::point3_t> truth = truth_while_holding(rogue, kPort);
    ASSERT_GE(truth.size(), 30u) << as_vision;
    for (const auto& p : truth) {
      ASSERT_GT(std::hypot(p.position[0] - 0.40, p.position[1] - 0.10, p.position[2] - 0.30), 0.05)
          << "the forged arm state moved the ball (as sg-vision: " << as_vision << ")";
    }
  }
}

// --write gives two videos OpenCV reads back frame by frame, a CSV row per frame, and the true
// calibration, which projects the CSV's ball centres to where the red is in the frames.
TEST(CameraSim, WritesVideosTruthAndCalibration) {
  const std::string dir = make_temp_dir() + "/run";
  const ProcessResult r = run({program("sg-camera-sim"), "--write", dir, "--frames", "10", "--rate",
                               "4", "--occlusion", "1.0:0.5"},
                              120s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream csv(dir + "/ground_truth.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("frame,utime,time_s,x_m,y_m,z_m,seen_left,seen_right", 0), 0u) << line;
  std::vector<std::vector<double>> rows;
  while (std::getline(csv, line)) {
    std::vector<double> row;
    std::stringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), 10u);
  EXPECT_EQ(rows[4][6], 0.0) << "t = 1.0 s is occluded";
  EXPECT_EQ(rows[0][6], 1.0);

  const vision::StereoCalibration calibration = vision::read_calibration(dir + "/calibration.yaml");
  cv::VideoCapture video(dir + "/left.avi");
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  cv::Mat frame;
  while (video.read(frame)) {
    ASSERT_EQ(frame.size(), cv::Size(640, 480));
    if (frames == 0) {  // the ball is where the calibration says: red around its projection
      const auto px = calibration.left.project({rows[0][3], rows[0][4], rows[0][5]});
      ASSERT_TRUE(px.has_value());
      const cv::Vec3b bgr = frame.at<cv::Vec3b>(cvRound(px->y()), cvRound(px->x()));
      EXPECT_GT(bgr[2], 120) << "red";
      EXPECT_LT(bgr[1], 90);
    }
    ++frames;
  }
  EXPECT_EQ(frames, 10);
  cv::VideoCapture right(dir + "/right.avi");
  EXPECT_EQ(static_cast<int>(right.get(cv::CAP_PROP_FRAME_COUNT)), 10);
}

// --snapshot writes the stereo pair side by side.
TEST(CameraSim, SnapshotIsAStereoPair) {
  const std::string png = make_temp_dir() + "/pair.png";
  const ProcessResult r = run({program("sg-camera-sim"), "--snapshot", png}, 60s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const cv::Mat pair = cv::imread(png);
  EXPECT_EQ(pair.size(), cv::Size(1280, 480));
}

// Bad input: one line, non-zero exit.
TEST(CameraSim, BadInputIsOneLine) {
  const std::string dir = make_temp_dir();
  std::ofstream(dir + "/bad.yaml") << "scenario:\n  kind: spiral\n";
  for (const auto& args : std::vector<std::vector<std::string>>{{"--config", dir + "/bad.yaml"},
                                                                {"--occlusion", "5-2"},
                                                                {"--rate", "-4"},
                                                                {"--write", "/proc/no/such/dir"}}) {
    std::vector<std::string> argv = {program("sg-camera-sim")};
    argv.insert(argv.end(), args.begin(), args.end());
    const ProcessResult r = run(argv, 60s);
    EXPECT_NE(r.exit_code, 0) << args[0];
    EXPECT_LT(r.exit_code, 128) << args[0] << " crashed";
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
  }
}

}  // namespace
}  // namespace sg::test
