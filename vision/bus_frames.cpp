#include "vision/bus_frames.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "common/clock.hpp"
#include "vision/image_message.hpp"

namespace sg::vision {
namespace {

using stereograsp::image_t;

/// CPU time of the whole process, every thread's, in seconds.
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

std::chrono::microseconds busy_wait_as_used(const VisionSettings& settings) {
  if (settings.realtime_priority > 0 && settings.busy_wait_ms > 0) {
    spdlog::info("vision.busy_wait_ms is not used at SCHED_FIFO: sleeping until frames come");
    return std::chrono::microseconds(0);
  }
  return std::chrono::microseconds(std::llround(settings.busy_wait_ms * 1000));
}

BusFrames::BusFrames(StereoPublisher& vision, const Settings& settings)
    : vision_(vision),
      pairer_(settings.pair_tolerance_us),
      workers_{DecodeWorker(settings.mode), DecodeWorker(settings.mode)},
      cadence_(settings.busy_wait),
      busy_wait_(settings.busy_wait),
      started_(std::chrono::steady_clock::now()),
      started_cpu_s_(process_cpu_seconds()) {}

void BusFrames::on_image(const image_t& m, const sg::ReceiveInfo& info) {
  const int64_t start = sg::now_utime();
  const auto arrival = FrameCadence::Clock::now();
  const size_t side = info.channel == "CAMERA_LEFT" ? 0 : 1;
  if (const std::string e = image_message_error(m); !e.empty()) return drop(info, e);
  auto message = std::make_shared<const image_t>(m);
  auto pair = pairer_.add(static_cast<int>(side), m.utime, message);
  if (!pair) {
    first_arrival_ = arrival;
    awake_ += polling_;
    workers_[side].post(std::move(message), window(side, m));
    // The pair's second image is decoded here: the other worker has nothing to take until the
    // next pair, and polling it would share the first image's core with its decode.
    workers_[1 - side].stay_awake_until({});
    first_waiting_ = true;
    return;
  }
  first_waiting_ = false;
  cadence_.arrived(first_arrival_);  // awake for the next pair's first image
  const Message messages[2] = {pair->first, pair->second};
  const cv::Mat* frames[2];
  std::string error;
  frames[side] = workers_[side].decode(messages[side], window(side, m), &error);
  if (!frames[side]) return drop(info, error);
  if (!(frames[1 - side] = collect(1 - side, messages[1 - side], &error))) return drop(info, error);
  const auto published =
      vision_.process(*frames[0], *frames[1], pair->first->frame_number, pair->first->utime);
  if (published.handed != 0) {  // the stopwatch stops at OBJECT_POSITION, not the blobs after
    pair_to_position_.add(published.handed - info.recv_utime);
    delivery_.add(start - info.recv_utime);
    handling_.add(published.handed - start);
    pair_to_return_.add(published.returned - info.recv_utime);
  }
  ++pairs_;
}

std::chrono::microseconds BusFrames::wait() {
  const auto now = FrameCadence::Clock::now();
  const std::chrono::microseconds sleep =
      cadence_.sleep_before_next(now, std::chrono::milliseconds(100));
  polling_ = sleep.count() == 0 && busy_wait_.count() > 0;
  if (!polling_) return sleep;
  if (!first_waiting_)
    for (auto& worker : workers_) worker.stay_awake_until(now + 2 * busy_wait_);
  return busy_wait_;  // the workers poll; this thread sleeps until a frame, or renews that
}

void BusFrames::report(uint64_t bus_errors) const {
  vision_.report(pairer_.unmatched(), bad_ + bus_errors);
  std::printf("second image received -> OBJECT_POSITION handed to the bus: %s (decode: %s)\n",
              pair_to_position_.summary().c_str(),
              workers_[0].decoder().mode() == FrameDecoder::Mode::kRegion ? "region" : "full");
  std::printf("  of which the delivery to the image's handler: %s\n", delivery_.summary().c_str());
  std::printf(
      "  (the camera channels read %s; the first image of a pair decoded by its worker "
      "%llu times, in line %llu times; %llu first images found sg-vision awake)\n",
      read_directly_ ? "directly, on sg-vision's own socket on the bus's group"
                     : "through LCM's subscription",
      static_cast<unsigned long long>(workers_[0].by_worker() + workers_[1].by_worker()),
      static_cast<unsigned long long>(workers_[0].by_caller() + workers_[1].by_caller()),
      static_cast<unsigned long long>(awake_));
  std::printf("  of which in the image's handler (decode, track, publish): %s\n",
              handling_.summary().c_str());
  std::printf(
      "second image received -> the bus's publish() of OBJECT_POSITION returned (its delivery "
      "to this host's subscribers included): %s\n",
      pair_to_return_.summary().c_str());
  const double cpu_s = process_cpu_seconds() - started_cpu_s_;
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  std::printf("CPU time: %.2f s in %.1f s (%.1f %% of one core), %.2f ms a pair\n", cpu_s, wall_s,
              100 * cpu_s / std::max(wall_s, 1e-9),
              pairs_ ? 1000 * cpu_s / static_cast<double>(pairs_) : 0.0);
}

void BusFrames::drop(const sg::ReceiveInfo& info, const std::string& error) {
  if (++bad_ <= 10 || bad_ % 1000 == 0)
    spdlog::warn("{}: dropped an image: {} ({} so far)", info.channel, error, bad_);
}

/// The waiting image's frame from its worker; decoded again here when the worker's is another
/// message's, or when the tracker now looks beyond what was decoded (a pair processed since),
/// but never again when the message did not decode.
const cv::Mat* BusFrames::collect(size_t side, const Message& message, std::string* error) {
  DecodeWorker& worker = workers_[side];
  const cv::Mat* frame = worker.collect(error);
  const cv::Size size(message->width, message->height);
  const cv::Rect want = window(side, *message);
  const cv::Rect need = want.empty() ? cv::Rect({}, size) : want;
  if (worker.message() == message && (!frame || (need & worker.decoder().decoded()) == need))
    return frame;  // decoded where the tracker looks, or not decodable (`error` says why)
  return worker.decode(message, want, error);
}

}  // namespace sg::vision
