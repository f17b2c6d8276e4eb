// sg-vision as a process: on the simulator's frames over LCM and from video files, against the
// simulator's truth; malformed images; a camera that is not there.

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "common/bus.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/wait.hpp"
#include "vision/image_message.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;

// Simulated cameras -> sg-vision -> OBJECT_POSITION within 5 mm of GROUND_TRUTH, every frame,
// blobs for both cameras; a malformed image_t and three datagrams that are not LCM's are each
// counted, said in one line, and dropped.
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
  bus.set_guard(vouching_as("sg-camera-sim"));  // sg-vision believes images only from the cameras
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
  bool listening = false;  // sg-vision announces itself once it has subscribed
  bus.subscribe<stereograsp::process_status_t>(
      "PROCESS_STATUS", [&](const auto& m, const auto&) { listening |= m.process == "sg-vision"; });
  ASSERT_TRUE(eventually(
      bus, [&] { return listening; }, 30s, "sg-vision's PROCESS_STATUS"));
  // A malformed image first: 640x480 BGR that holds 100 bytes.
  stereograsp::image_t bad{};
  bad.width = 640, bad.height = 480, bad.row_stride = 1920;
  bad.pixel_format = stereograsp::image_t::FORMAT_BGR8;
  bad.size = 100;
  bad.data.assign(100, 7);
  bus.publish("CAMERA_LEFT", bad);
  // Then bytes LCM would never send, read on sg-vision's own socket (vision.camera_read: direct):
  // not LCM's at all; a first fragment of CAMERA_LEFT claiming 1 GB; and a CAMERA_LEFT of three
  // fragments whose second never comes. Each is one decode error; nothing else changes.
  send_raw_datagrams(kPort, {{'G', 'E', 'T', ' ', '/', '\n'}});
  const auto fragment = [](uint32_t size, uint32_t offset, uint16_t no, const char* channel) {
    std::vector<uint8_t> d = {'L', 'C', '0', '3', 0, 0, 0, 9};
    for (const uint32_t v : {size, offset}) {
      for (int shift = 24; shift >= 0; shift -= 8) d.push_back(static_cast<uint8_t>(v >> shift));
    }
    d.insert(d.end(), {0, static_cast<uint8_t>(no), 0, 3});
    if (no == 0) d.insert(d.end(), channel, channel + std::strlen(channel) + 1);  // and its NUL
    d.resize(d.size() + 100, 7);
    return d;
  };
  send_raw_datagrams(kPort, {fragment(1u << 30, 0, 0, "CAMERA_LEFT")});
  send_raw_datagrams(kPort, {fragment(300, 0, 0, "CAMERA_LEFT"), fragment(300, 200, 2, "")});
  // Every frame counts here: the simulator renders each one, however late (a loaded machine).
  Child sim({program("sg-camera-sim"), "--rate", "10", "--frames", "30", "--max-lag", "0",
             "--lcm-url", url});
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (measured.size() < 30 && std::chrono::steady_clock::now() < deadline) bus.handle(100ms);
  while (bus.handle(300ms)) {  // the last frame's blobs follow its position
  }
  EXPECT_EQ(sim.wait(30s).exit_code, 0);
  const ProcessResult v = vision.wait(30s);
  EXPECT_EQ(v.exit_code, 0) << v.err;
  EXPECT_NE(v.out.find("processed 30 stereo frames: ball found left 100.0%, right 100.0%"),
            std::string::npos)
      << v.out;
  EXPECT_NE(v.out.find("4 bad images"), std::string::npos) << v.out;
  EXPECT_NE(v.err.find("dropped an image"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("not an LCM datagram (magic 0x47455420)"), std::string::npos) << v.err;
  EXPECT_NE(v.err.find("CAMERA_LEFT: a 1073741824-byte message, above the bound"),
            std::string::npos)
      << v.err;
  EXPECT_NE(v.err.find("CAMERA_LEFT: message 9 (300 bytes, 1 of 3 fragments) dropped: fragment 2 "
                       "came where 1 was due"),
            std::string::npos)
      << v.err;
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
    EXPECT_EQ(p.flags, 0);
    EXPECT_GT(p.position_sigma[0], 0.0);
    EXPECT_LT(p.position_sigma[0], 0.005);
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

/// Fraction of the pixels along a rectangle's top and bottom edges that are yellow.
double yellow_on_edges(const cv::Mat& frame, const cv::Rect& r) {
  int yellow = 0, total = 0;
  for (int y : {r.y, r.y + r.height - 1}) {  // cv::rectangle draws the last row at y + h - 1
    for (int x = r.x + 4; x < r.x + r.width - 4; ++x) {
      if (y < 0 || y >= frame.rows || x < 0 || x >= frame.cols) continue;
      const cv::Vec3b p = frame.at<cv::Vec3b>(y, x);
      yellow += p[2] > 170 && p[1] > 170 && p[0] < 110;
      ++total;
    }
  }
  return total ? double(yellow) / total : 0.0;
}

// sg-viewer --record: every recorded frame shows the yellow search window where the blob's was.
TEST(Viewer, RecordedViewShowsTheSearchWindowWhereTheBlobWas) {
  constexpr int kPort = 7911;
  ASSERT_TRUE(multicast_available(kPort));
  const std::string url = test_url(kPort);
  const std::string dir = make_temp_dir();
  Bus bus(url);
  std::map<int64_t, std::array<cv::Rect, 2>> windows;
  bus.subscribe<stereograsp::blob_t>("BLOB_.*", [&](const stereograsp::blob_t& b, const auto&) {
    windows[b.utime][static_cast<size_t>(b.camera)] =
        cv::Rect(b.search_window[0], b.search_window[1], b.search_window[2], b.search_window[3]);
  });
  Child viewer({program("sg-viewer"), "--record", dir + "/view.avi", "--frames", "15",
                "--no-window", "--lcm-url", url});
  Child vision({program("sg-vision"), "--frames", "20", "--lcm-url", url});
  ASSERT_TRUE(
      eventually([&] { return joined_bus(viewer.pid(), kPort) && joined_bus(vision.pid(), kPort); },
                 30s, "sg-viewer and sg-vision to join the bus"));
  Child sim({program("sg-camera-sim"), "--rate", "10", "--frames", "20", "--max-lag", "0",
             "--lcm-url", url});
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (windows.size() < 20 && std::chrono::steady_clock::now() < deadline) bus.handle(100ms);
  const ProcessResult drawn = viewer.wait(30s);
  ASSERT_EQ(drawn.exit_code, 0) << drawn.err;
  EXPECT_NE(drawn.out.find("drew 15 frames"), std::string::npos) << drawn.out;

  std::ifstream csv(dir + "/view.avi.csv");
  std::string line;
  std::getline(csv, line);
  cv::VideoCapture video(dir + "/view.avi");
  ASSERT_TRUE(video.isOpened());
  cv::Mat frame;
  int checked = 0;
  while (video.read(frame) && std::getline(csv, line)) {
    const int64_t utime = std::stoll(line.substr(line.find(',') + 1));
    ASSERT_TRUE(windows.count(utime)) << "a recorded frame's utime is a published frame's";
    ASSERT_EQ(frame.cols, 1280);
    for (int cam = 0; cam < 2; ++cam) {
      const cv::Rect w = windows[utime][static_cast<size_t>(cam)] + cv::Point(cam * 640, 0);
      EXPECT_GT(yellow_on_edges(frame, w), 0.8) << "frame " << checked << " camera " << cam;
      EXPECT_LT(yellow_on_edges(frame, w + cv::Point(0, 25)), 0.2) << "and not elsewhere";
    }
    ++checked;
  }
  EXPECT_EQ(checked, 15);
}

// Two folders of images, paired by name; --publish-images republishes them as JPEG image_t.
TEST(Vision, ImageFoldersSourceRepublishesFrames) {
  constexpr int kPort = 7912;
  ASSERT_TRUE(multicast_available(kPort));
  const std::string dir = make_temp_dir();
  ASSERT_EQ(run({program("sg-camera-sim"), "--write", dir, "--frames", "6"}, 120s).exit_code, 0);
  for (const char* side : {"left", "right"}) {
    std::filesystem::create_directory(dir + "/" + side);
    cv::VideoCapture video(dir + "/" + side + ".avi");
    cv::Mat frame;
    for (int k = 0; video.read(frame); ++k) {
      cv::imwrite(dir + "/" + side + "/frame" + std::to_string(100 + k) + ".png", frame);
    }
  }
  Bus bus(test_url(kPort));
  int images = 0, blobs = 0;
  bus.subscribe<stereograsp::image_t>("CAMERA_.*", [&](const auto& m, const auto&) {
    std::string error;
    images += sg::vision::decode_image(m, &error).has_value();
  });
  bus.subscribe<stereograsp::blob_t>("BLOB_.*",
                                     [&](const auto& b, const auto&) { blobs += b.found; });
  const ProcessResult v =
      run({program("sg-vision"), "--source", "images", "--left", dir + "/left", "--right",
           dir + "/right", "--publish-images", "--rate", "10", "--lcm-url", test_url(kPort)},
          60s);
  EXPECT_EQ(v.exit_code, 0) << v.err;
  while (bus.handle(300ms)) {
  }
  EXPECT_NE(v.out.find("processed 6 stereo frames: ball found left 100.0%, right 100.0%"),
            std::string::npos)
      << v.out;
  EXPECT_EQ(images, 12);
  EXPECT_EQ(blobs, 12);
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
