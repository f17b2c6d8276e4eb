// DecodeWorker: a camera's decode on a thread of its own gives the frame FrameDecoder gives in
// line, whether the worker or the caller did it, and a message that does not decode is refused
// with FrameDecoder's reason.

#include "vision/decode_worker.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <ctime>
#include <thread>

#include "sim/camera_simulator.hpp"
#include "tests/support/wait.hpp"
#include "vision/image_message.hpp"

namespace sg::vision {
namespace {

using namespace std::chrono_literals;
using stereograsp::image_t;

std::vector<std::shared_ptr<const image_t>> lab_frames(int count) {
  sim::SimParams params;
  sim::CameraSimulator sim(params);
  sim::StereoFrame frame;
  std::vector<std::shared_ptr<const image_t>> out;
  for (int64_t n = 0; n < count; ++n) {
    sim.render(n, {}, frame);
    out.push_back(std::make_shared<const image_t>(encode_image(frame.image[0], 0, n, n, true)));
  }
  return out;
}

// Twenty frames, windows moving: each collected frame equals FrameDecoder's own within the
// window, and every post was decoded by the worker or by the caller, once.
TEST(DecodeWorker, CollectsWhatFrameDecoderDecodes) {
  DecodeWorker worker(FrameDecoder::Mode::kRegion);
  FrameDecoder inline_decoder(FrameDecoder::Mode::kRegion);
  const auto frames = lab_frames(20);
  for (size_t n = 0; n < frames.size(); ++n) {
    SCOPED_TRACE(n);
    const cv::Rect window(40 + 20 * static_cast<int>(n), 100, 120, 90);
    worker.post(frames[n], window);
    if (n % 2 == 0) {  // even frames: let the worker take it; odd: collect at once (either may)
      ASSERT_TRUE(test::eventually([&] { return worker.taken(); }, 10s, "the worker's decode"));
    }
    std::string error, inline_error;
    const cv::Mat* got = worker.collect(&error);
    const cv::Mat* want = inline_decoder.decode(*frames[n], window, &inline_error);
    ASSERT_NE(got, nullptr) << error;
    ASSERT_NE(want, nullptr) << inline_error;
    EXPECT_EQ(cv::norm((*got)(window), (*want)(window), cv::NORM_INF), 0.0);
    EXPECT_EQ(worker.decoder().decoded(), inline_decoder.decoded());
    EXPECT_EQ(worker.message(), frames[n]);
    EXPECT_EQ(worker.collect(&error), got) << "collecting again gives the same frame";
  }
  EXPECT_EQ(worker.by_worker() + worker.by_caller(), frames.size());
  EXPECT_GE(worker.by_worker(), frames.size() / 2);
}

// A message that does not decode: nullptr and FrameDecoder's one line; nothing before a post.
TEST(DecodeWorker, RefusesWithFrameDecodersReason) {
  DecodeWorker worker(FrameDecoder::Mode::kRegion);
  std::string error;
  EXPECT_EQ(worker.collect(&error), nullptr);
  EXPECT_EQ(error, "nothing was posted");
  image_t m = encode_image(cv::Mat(48, 64, CV_8UC3, cv::Scalar(20, 40, 200)), 0, 1, 10, true);
  m.width = 32;
  worker.post(std::make_shared<const image_t>(m), {});
  EXPECT_EQ(worker.collect(&error), nullptr);
  EXPECT_EQ(error, "JPEG header declares 64x48, the message 32x48");
}

// Posting again before collecting: the first decode is finished and discarded, the second wins;
// destroying a worker with a decode posted joins its thread.
TEST(DecodeWorker, ANewPostReplacesTheLast) {
  const auto frames = lab_frames(2);
  DecodeWorker worker(FrameDecoder::Mode::kFull);
  worker.post(frames[0], {});
  worker.post(frames[1], {});
  std::string error;
  const cv::Mat* got = worker.collect(&error);
  ASSERT_NE(got, nullptr) << error;
  FrameDecoder inline_decoder(FrameDecoder::Mode::kFull);
  EXPECT_EQ(cv::norm(*got, *inline_decoder.decode(*frames[1], {}, &error), cv::NORM_INF), 0.0);
  DecodeWorker abandoned(FrameDecoder::Mode::kFull);
  abandoned.post(frames[0], {});
}

/// CPU time this process has used: a worker polling adds to it, one asleep does not.
std::chrono::microseconds process_cpu_time() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return std::chrono::seconds(t.tv_sec) + std::chrono::microseconds(t.tv_nsec / 1000);
}

// Kept awake, the worker polls (the process uses CPU while its only other thread sleeps) and
// still decodes what FrameDecoder decodes; after that time it sleeps again (no CPU) and a post
// still wakes it; destroying it while awake joins its thread.
TEST(DecodeWorker, AwakeUntilATimeThenAsleep) {
  const auto frames = lab_frames(2);
  DecodeWorker worker(FrameDecoder::Mode::kFull);
  const auto until = std::chrono::steady_clock::now() + 300ms;
  worker.stay_awake_until(until);
  const auto awake_from = process_cpu_time();
  std::this_thread::sleep_for(200ms);
  EXPECT_GT(process_cpu_time() - awake_from, 5ms) << "awake: polling";
  std::this_thread::sleep_until(until + 50ms);
  const auto asleep_from = process_cpu_time();
  std::this_thread::sleep_for(200ms);
  EXPECT_LT(process_cpu_time() - asleep_from, 5ms) << "asleep after the time";
  std::string error;
  FrameDecoder inline_decoder(FrameDecoder::Mode::kFull);
  for (const auto& frame : frames) {
    worker.post(frame, {});
    ASSERT_TRUE(test::eventually([&] { return worker.taken(); }, 10s, "the worker's decode"));
    const cv::Mat* got = worker.collect(&error);
    ASSERT_NE(got, nullptr) << error;
    EXPECT_EQ(cv::norm(*got, *inline_decoder.decode(*frame, {}, &error), cv::NORM_INF), 0.0);
    worker.stay_awake_until(std::chrono::steady_clock::now() + 1h);  // destroyed awake
  }
  EXPECT_EQ(worker.by_worker(), frames.size());
}

}  // namespace
}  // namespace sg::vision
