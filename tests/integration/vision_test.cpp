// sg-vision as a process: on the simulator's frames over LCM and from video files, against the
// simulator's truth; malformed images; a camera that is not there.

#include <gtest/gtest.h>

#include <map>
#include <thread>

#include "common/bus.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "vision/image_message.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;

// Simulated cameras -> sg-vision -> OBJECT_POSITION within 5 mm of GROUND_TRUTH, every frame,
// blobs for both cameras; then a malformed image_t is counted and dropped.
TEST(Vision, PositionsFromSimulatedCamerasMatchTheTruth) {
  constexpr int kPort = 7909;
  ASSERT_TRUE(multicast_available(kPort));
  const std::string url = test_url(kPort);
  const std::string dir = make_temp_dir();
  ASSERT_EQ(run({program("sg-camera-sim"), "--snapshot", dir + "/pair.png", "--calibration-out",
                 dir + "/cams.yaml"})
                .exit_code,
            0);
  Bus bus(url);
  std::map<int64_t, stereograsp::point3_t> truth, measured;
  int blobs = 0;
  bus.subscribe<stereograsp::point3_t>("GROUND_TRUTH",
                                       [&](const auto& m, const auto&) { truth[m.utime] = m; });
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION",
                                       [&](const auto& m, const auto&) { measured[m.utime] = m; });
  bus.subscribe<stereograsp::blob_t>("BLOB_.*",
                                     [&](const auto& m, const auto&) { blobs += m.found; });
  Child vision({program("sg-vision"), "--calibration", dir + "/cams.yaml", "--frames", "30",
                "--lcm-url", url});
  std::this_thread::sleep_for(1s);
  // A malformed image first: 640x480 BGR that holds 100 bytes.
  stereograsp::image_t bad{};
  bad.width = 640, bad.height = 480, bad.row_stride = 1920;
  bad.pixel_format = stereograsp::image_t::FORMAT_BGR8;
  bad.size = 100;
  bad.data.assign(100, 7);
  bus.publish("CAMERA_LEFT", bad);
  Child sim({program("sg-camera-sim"), "--rate", "10", "--frames", "30", "--lcm-url", url});
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (measured.size() < 30 && std::chrono::steady_clock::now() < deadline) bus.handle(100ms);
  EXPECT_EQ(sim.wait(30s).exit_code, 0);
  const ProcessResult v = vision.wait(30s);
  EXPECT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("processed 30 stereo frames: ball found left 100.0%, right 100.0%"),
            std::string::npos)
      << v.out;
  EXPECT_NE(v.out.find("1 bad images"), std::string::npos) << v.out;
  EXPECT_NE(v.err.find("dropped an image"), std::string::npos) << v.err;
  ASSERT_EQ(measured.size(), 30u);
  EXPECT_EQ(blobs, 60);
  double worst = 0;
  for (const auto& [utime, p] : measured) {
    ASSERT_TRUE(truth.count(utime)) << "OBJECT_POSITION carries the frames' capture time";
    EXPECT_TRUE(p.visible);
    const auto& t = truth.at(utime);
    const double error = std::hypot(p.position[0] - t.position[0], p.position[1] - t.position[1],
                                    p.position[2] - t.position[2]);
    worst = std::max(worst, error);
    EXPECT_LT(p.reprojection_error, 1.0);
  }
  EXPECT_LT(worst, 0.005);
  std::printf("worst 3D error over 30 frames: %.2f mm\n", worst * 1000);
}

// Video files written by the simulator, read back by sg-vision: the ball in every frame.
TEST(Vision, VideoFilesSource) {
  constexpr int kPort = 7910;
  ASSERT_TRUE(multicast_available(kPort));
  const std::string dir = make_temp_dir();
  ASSERT_EQ(run({program("sg-camera-sim"), "--write", dir, "--frames", "20", "--rate", "4"}, 120s)
                .exit_code,
            0);
  const ProcessResult v = run({program("sg-vision"), "--source", "video", "--left",
                               dir + "/left.avi", "--right", dir + "/right.avi", "--calibration",
                               dir + "/calibration.yaml", "--lcm-url", test_url(kPort)},
                              120s);
  EXPECT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("processed 20 stereo frames: ball found left 100.0%, right 100.0%"),
            std::string::npos)
      << v.out;
}

// learn-color prints config lines; bad input is one line and a non-zero exit.
TEST(Vision, LearnColorAndBadInput) {
  const std::string dir = make_temp_dir();
  ASSERT_EQ(run({program("sg-camera-sim"), "--snapshot", dir + "/pair.png"}).exit_code, 0);
  const ProcessResult learned =
      run({program("sg-vision"), "learn-color", dir + "/pair.png", "--roi", "a,b,c,d"});
  EXPECT_NE(learned.exit_code, 0) << "not x,y,w,h";
  EXPECT_EQ(count_lines(learned.err), 1) << learned.err;
  const ProcessResult wall =
      run({program("sg-vision"), "learn-color", dir + "/pair.png", "--roi", "10,10,8,8"});
  EXPECT_EQ(wall.exit_code, 0) << wall.err;
  EXPECT_NE(wall.out.find("  r_range: ["), std::string::npos) << wall.out;
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"--source", "v4l2", "--left", "/dev/video97", "--right", "/dev/video98"},
           {"--source", "video", "--left", dir + "/none.avi", "--right", dir + "/none.avi"},
           {"--source", "images", "--left", dir, "--right", "/nonexistent"},
           {"--calibration", dir + "/pair.png"}}) {
    std::vector<std::string> argv = {program("sg-vision")};
    argv.insert(argv.end(), args.begin(), args.end());
    const ProcessResult r = run(argv, 30s);
    EXPECT_NE(r.exit_code, 0) << args[1];
    EXPECT_LT(r.exit_code, 128) << args[1];
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
  }
}

}  // namespace
}  // namespace sg::test
