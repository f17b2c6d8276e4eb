#pragma once

/// sg-vision's frames from the bus: CAMERA_LEFT and CAMERA_RIGHT images paired as messages
/// (stereo_pairer.hpp), each decoded only where its tracker will look (frame_decoder.hpp), and
/// handed to the StereoPublisher. A pair's first image goes to its camera's DecodeWorker as it
/// arrives; the second is decoded in line when it completes the pair, so the two decode at once.
/// Each pair is timed from the kernel's receipt of its second image to OBJECT_POSITION handed to
/// the bus (sg-vision's own latency, issue 19).
///
///     sg::vision::BusFrames frames(publisher, {.pair_tolerance_us = 5000});
///     auto on_image = [&](const image_t& m, const sg::ReceiveInfo& i) { frames.on_image(m, i); };
///     bus.subscribe<image_t>("CAMERA_LEFT", on_image);
///     bus.subscribe<image_t>("CAMERA_RIGHT", on_image);
///     bus.spin([&] { return true; }, [&] { return frames.wait(); });
///     frames.report(bus.decode_errors());
///
/// Bad images (image_message_error(), or undecodable) are dropped, counted and logged (the
/// first ten, then every thousandth).

#include <chrono>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "common/bus.hpp"
#include "common/latency_record.hpp"
#include "stereograsp/image_t.hpp"
#include "vision/decode_worker.hpp"
#include "vision/frame_cadence.hpp"
#include "vision/frame_decoder.hpp"
#include "vision/stereo_pairer.hpp"
#include "vision/stereo_publisher.hpp"
#include "vision/vision_config.hpp"

namespace sg::vision {

/// vision.busy_wait_ms as sg-vision uses it: zero at SCHED_FIFO (settings.realtime_priority >
/// 0), where a thread that polls keeps the kernel's own threads (ksoftirqd, which may be
/// delivering the frame) off its core.
std::chrono::microseconds busy_wait_as_used(const VisionSettings& settings);

class BusFrames {
 public:
  using Message = std::shared_ptr<const stereograsp::image_t>;

  struct Settings {
    int64_t pair_tolerance_us = 5000;  ///< largest utime difference within a pair
    FrameDecoder::Mode mode = FrameDecoder::Mode::kRegion;
    /// How long the decode workers poll around a pair's due time (busy_wait_as_used()).
    std::chrono::microseconds busy_wait{0};
  };

  BusFrames(StereoPublisher& vision, const Settings& settings);

  /// One camera image, as the bus delivered it.
  void on_image(const stereograsp::image_t& m, const sg::ReceiveInfo& info);

  /// Pairs processed.
  int64_t pairs() const { return pairs_; }

  /// How long to sleep waiting for a message now: none around the next pair's due time.
  /// While a pair is due, and until its first image comes, the decode workers stay awake too, so
  /// that the first image's decode is already running on the other core when it comes
  /// (decode_worker.hpp).
  std::chrono::microseconds wait();

  /// Whether the camera channels are read on sg-vision's own socket (for the report).
  void set_read_directly(bool direct) { read_directly_ = direct; }

  /// Prints the summary: the publisher's, then the latencies and the CPU time.
  void report(uint64_t bus_errors) const;

 private:
  void drop(const sg::ReceiveInfo& info, const std::string& error);
  cv::Rect window(size_t side, const stereograsp::image_t& m) const {
    return vision_.next_window(side, cv::Size(m.width, m.height));
  }
  const cv::Mat* collect(size_t side, const Message& message, std::string* error);

  StereoPublisher& vision_;
  StereoPairer<Message> pairer_;
  DecodeWorker workers_[2];
  FrameCadence cadence_;
  std::chrono::microseconds busy_wait_;
  FrameCadence::Clock::time_point first_arrival_{};
  bool polling_ = false;        // a pair is due: the workers poll (busy_wait)
  bool first_waiting_ = false;  // a pair's first image is posted, its second not yet come
  uint64_t awake_ = 0;          // pairs whose first image found it so
  sg::LatencyRecord pair_to_position_, delivery_, handling_, pair_to_return_;
  uint64_t bad_ = 0;
  int64_t pairs_ = 0;
  bool read_directly_ = false;
  std::chrono::steady_clock::time_point started_;
  double started_cpu_s_;  // the process's CPU time (every thread's) then
};

}  // namespace sg::vision
