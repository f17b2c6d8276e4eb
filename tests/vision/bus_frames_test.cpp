// BusFrames: sg-vision's camera images from the bus, paired, decoded where the tracker looks,
// tracked, and published through the StereoPublisher; bad and unpaired images are counted, not
// fatal. Driven over memq:// with the camera simulator's JPEGs and its true calibration.

#include "vision/bus_frames.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "common/clock.hpp"
#include "sim/camera_simulator.hpp"
#include "vision/image_message.hpp"

namespace sg::vision {
namespace {

using namespace std::chrono_literals;
using stereograsp::blob_t;
using stereograsp::image_t;
using stereograsp::point3_t;

/// The simulator's own cameras, as sg-camera-sim writes them (--calibration-out).
StereoCalibration true_calibration(const sim::CameraSimulator& sim) {
  StereoCalibration c;
  c.left = sim.camera(0);
  c.right = sim.camera(1);
  return c;
}

struct Rig {
  sim::SimParams params;
  sim::CameraSimulator sim{params};
  Bus bus{"memq://"};
  StereoPublisher publisher{bus, VisionSettings{}, {640, 480}, true_calibration(sim), false};
  std::vector<point3_t> positions;
  std::vector<blob_t> blobs[2];

  Rig() {
    bus.subscribe<point3_t>("OBJECT_POSITION",
                            [&](const point3_t& p, const ReceiveInfo&) { positions.push_back(p); });
    bus.subscribe<blob_t>("BLOB_LEFT",
                          [&](const blob_t& b, const ReceiveInfo&) { blobs[0].push_back(b); });
    bus.subscribe<blob_t>("BLOB_RIGHT",
                          [&](const blob_t& b, const ReceiveInfo&) { blobs[1].push_back(b); });
  }

  /// Frame n's JPEGs, stamped n * 50 ms.
  std::array<image_t, 2> images(int64_t n, sim::StereoFrame& frame) {
    sim.render(n, {}, frame);
    return {encode_image(frame.image[0], 0, n, n * 50000, true),
            encode_image(frame.image[1], 1, n, n * 50000, true)};
  }

  void deliver(BusFrames& frames, const image_t& image) {
    frames.on_image(image, {image.camera == 0 ? "CAMERA_LEFT" : "CAMERA_RIGHT", now_utime(),
                            image.getEncodedSize()});
    while (bus.handle(0ms)) {
    }
  }
};

// Twenty pairs, arriving left first and right first in turn: one BLOB_LEFT, one BLOB_RIGHT and
// one OBJECT_POSITION per pair, stamped with the pair's capture time, placing the ball within
// 5 mm of where the simulator drew it.
TEST(BusFrames, EachPairIsTrackedAndPlaced) {
  Rig rig;
  BusFrames frames(rig.publisher, {});
  sim::StereoFrame frame;
  std::vector<Eigen::Vector3d> truth;
  for (int64_t n = 0; n < 20; ++n) {
    const auto images = rig.images(n, frame);
    truth.push_back(frame.ball);
    const size_t first = n % 2;
    rig.deliver(frames, images[first]);
    rig.deliver(frames, images[1 - first]);
  }
  EXPECT_EQ(frames.pairs(), 20);
  ASSERT_EQ(rig.blobs[0].size(), 20u);
  ASSERT_EQ(rig.blobs[1].size(), 20u);
  ASSERT_EQ(rig.positions.size(), 20u);
  for (size_t n = 0; n < 20; ++n) {
    SCOPED_TRACE(n);
    EXPECT_EQ(rig.blobs[0][n].utime, static_cast<int64_t>(n) * 50000);
    EXPECT_EQ(rig.positions[n].utime, static_cast<int64_t>(n) * 50000);
    const Eigen::Vector3d p(rig.positions[n].position[0], rig.positions[n].position[1],
                            rig.positions[n].position[2]);
    EXPECT_LT((p - truth[n]).norm(), 0.005) << p.transpose() << " vs " << truth[n].transpose();
  }
}

// A malformed image and a JPEG that does not decode are dropped and counted as bad images; the
// two images whose partners never come (one of them the broken JPEG's) are counted as unmatched;
// the pairs around them go through.
TEST(BusFrames, BadAndUnpairedImagesAreCountedNotFatal) {
  Rig rig;
  BusFrames frames(rig.publisher, {});
  sim::StereoFrame frame;
  auto images = rig.images(0, frame);
  rig.deliver(frames, images[0]);
  rig.deliver(frames, images[1]);

  image_t malformed = rig.images(1, frame)[0];
  malformed.width = -5;  // image_message_error() refuses it
  rig.deliver(frames, malformed);
  image_t broken = rig.images(2, frame)[0];
  broken.data.assign(broken.data.size(), 0x55);  // no JPEG marker anywhere
  rig.deliver(frames, broken);
  rig.deliver(frames, rig.images(2, frame)[1]);  // the broken image's partner: never paired

  rig.deliver(frames, rig.images(3, frame)[0]);  // its right image never comes
  images = rig.images(4, frame);
  rig.deliver(frames, images[1]);
  rig.deliver(frames, images[0]);

  EXPECT_EQ(frames.pairs(), 2);
  EXPECT_EQ(rig.blobs[0].size(), 2u);
  testing::internal::CaptureStdout();
  frames.report(0);
  const std::string report = testing::internal::GetCapturedStdout();
  EXPECT_NE(report.find("processed 2 stereo frames"), std::string::npos) << report;
  EXPECT_NE(report.find("2 bad images"), std::string::npos) << report;
  EXPECT_NE(report.find("; 2 unmatched frames"), std::string::npos) << report;
}

}  // namespace
}  // namespace sg::vision
