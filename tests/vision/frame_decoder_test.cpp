// FrameDecoder with the stereo step, as sg-vision runs them: on the simulated lab's JPEG frames,
// decoding only the trackers' windows gives the same blobs and positions, bit for bit, as
// decoding every frame whole, while decoding a small part of each frame; and a message that is
// not what it says is refused in one line.

#include "vision/frame_decoder.hpp"

#include <gtest/gtest.h>

#include "common/message_types.hpp"
#include "sim/camera_simulator.hpp"
#include "vision/image_message.hpp"
#include "vision/stereo_step.hpp"

namespace sg::vision {
namespace {

using stereograsp::image_t;

/// One pipeline: a decoder per camera and the stereo step, fed messages.
struct Pipeline {
  Pipeline(FrameDecoder::Mode mode, const StereoCalibration& cal)
      : decoders{FrameDecoder(mode), FrameDecoder(mode)},
        step({}, {cal.left.width(), cal.left.height()}, cal,
             StereoMatchParams{.ball_radius = 0.035}) {}
  StereoOutput run(const std::array<image_t, 2>& m) {
    std::array<const cv::Mat*, 2> f{};
    for (size_t i = 0; i < 2; ++i) {
      std::string error;
      f[i] = decoders[i].decode(m[i], step.next_window(i, {m[i].width, m[i].height}), &error);
      EXPECT_NE(f[i], nullptr) << error;
    }
    return step.process(*f[0], *f[1], m[0].frame_number, m[0].utime);
  }
  std::array<FrameDecoder, 2> decoders;
  StereoStep step;
};

// 300 frames (10 s) of the simulated lab: every blob and OBJECT_POSITION of the region pipeline
// equals the full pipeline's; in tracking mode each camera decoded only its window, 4 px around
// it and the iMCUs they touch, under a quarter of its frame.
TEST(FrameDecoder, RegionDecodingTracksAsFullDecodingDoes) {
  sim::SimParams params;
  sim::CameraSimulator sim(params);
  StereoCalibration cal;
  cal.left = sim.camera(0), cal.right = sim.camera(1);
  Pipeline full(FrameDecoder::Mode::kFull, cal), region(FrameDecoder::Mode::kRegion, cal);
  sim::StereoFrame frame;
  int tracking = 0, small = 0, visible = 0;
  for (int64_t n = 0; n < 300; ++n) {
    SCOPED_TRACE(n);
    sim.render(n, {}, frame);
    std::array<image_t, 2> m;
    for (size_t i = 0; i < 2; ++i)
      m[i] = encode_image(frame.image[i], static_cast<int8_t>(i), n, 1000 + n * 33333, true);
    const StereoOutput a = full.run(m), b = region.run(m);
    for (size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(sg::encode_message(a.blob[i]), sg::encode_message(b.blob[i]));  // every field
      if (b.observation[i].tracking) {
        ++tracking;
        // the window, 4 px around it, and the alignment of its top left to an iMCU (16 px)
        const cv::Rect w = b.observation[i].window, d = region.decoders[i].decoded();
        const cv::Rect reach(w.x - 4 - 15, w.y - 4 - 15, w.width + 8 + 15, w.height + 8 + 15);
        small += (d & reach) == d && d.area() * 4 < m[i].width * m[i].height;
      }
    }
    ASSERT_TRUE(a.position && b.position);
    visible += b.position->visible;
    EXPECT_EQ(sg::encode_message(*a.position), sg::encode_message(*b.position));
  }
  EXPECT_GT(visible, 250);
  EXPECT_GT(tracking, 500);
  EXPECT_EQ(small, tracking);
}

// A size field that is not the data's, a JPEG that declares another size, an unknown format:
// refused with the reason, no frame.
TEST(FrameDecoder, RefusesWhatIsNotWhatItSays) {
  const cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(20, 40, 200));
  FrameDecoder decoder;
  std::string error;
  image_t m = encode_image(bgr, 0, 1, 10, true);
  m.size += 1;
  EXPECT_EQ(decoder.decode(m, {}, &error), nullptr);
  EXPECT_EQ(error, "size field does not match the data");
  m = encode_image(bgr, 0, 1, 10, true);
  m.width = 32;
  EXPECT_EQ(decoder.decode(m, {}, &error), nullptr);
  EXPECT_EQ(error, "JPEG header declares 64x48, the message 32x48");
  m = encode_image(bgr, 0, 1, 10, false);
  m.pixel_format = 77;
  EXPECT_EQ(decoder.decode(m, {}, &error), nullptr);
  EXPECT_EQ(error, "unknown pixel_format 77");
  m.pixel_format = image_t::FORMAT_BGR8;
  const cv::Mat* ok = decoder.decode(m, {}, &error);
  ASSERT_NE(ok, nullptr) << error;
  EXPECT_EQ(cv::norm(*ok, bgr, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace sg::vision
