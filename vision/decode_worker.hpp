#pragma once

/// One camera's FrameDecoder on a thread of its own, which the caller can always overtake
/// (issue 19). sg-vision posts the first image of a stereo pair as it arrives, goes on reading
/// the bus, and collects the frame when the second image completes the pair: the two windows are
/// decoded on two cores at once, not one after the other.
///
///     DecodeWorker left(FrameDecoder::Mode::kRegion);
///     left.post(message, step.next_window(0, size));  // returns at once
///     ...                                             // decode the right image meanwhile
///     std::string error;
///     const cv::Mat* frame = left.collect(&error);    // nullptr: `error` says why
///
/// A late worker never costs more than decoding in line: collect() decodes the posted message on
/// the caller's thread when the worker has not begun it (a thread woken late, as this lab's
/// virtual machine sometimes wakes them), and waits only for a decode under way, spinning with
/// yields rather than sleeping, so no second wake-up lies on the frame's path.
///
/// Awake when due: stay_awake_until() keeps the worker polling for a post, yielding the core,
/// instead of sleeping, until a time (sg-vision: while a pair is due, vision.busy_wait_ms). On the
/// lab's 2-vCPU virtual machine a sleeping worker is woken on the poster's own vCPU and preempts
/// it, or on the other one about 0.1-0.2 ms late; an awake one takes the first image at once on
/// the other vCPU (docs/performance.md, issue 19).
///
/// Lifecycle: the thread starts with the object and is joined by its destructor (after the decode
/// under way, if any). post() and collect() are for one thread, the owner's; the frame collect()
/// returns stays valid until the next post().

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <thread>

#include "stereograsp/image_t.hpp"
#include "vision/frame_decoder.hpp"

namespace sg::vision {

class DecodeWorker {
 public:
  explicit DecodeWorker(FrameDecoder::Mode mode);
  ~DecodeWorker();
  DecodeWorker(const DecodeWorker&) = delete;
  DecodeWorker& operator=(const DecodeWorker&) = delete;

  /// Hands `message` to the worker, to decode at least `region` of it (FrameDecoder::decode).
  /// A decode still posted is collected (and discarded) first.
  void post(std::shared_ptr<const stereograsp::image_t> message, cv::Rect region);

  /// The frame of the last post(), decoded by the worker or, when it had not begun, here; nullptr
  /// with `error` set when the message does not decode (or nothing was posted).
  const cv::Mat* collect(std::string* error);

  /// The message of the last post() (nullptr before the first).
  const std::shared_ptr<const stereograsp::image_t>& message() const { return message_; }
  /// Its decoder: decoded() says which pixels the last decode filled. Valid after collect().
  const FrameDecoder& decoder() const { return decoder_; }

  /// True once the worker has begun (or finished) the posted decode; false before, and when
  /// nothing is posted.
  bool taken() const {
    const int s = state_.load(std::memory_order_acquire);
    return s == kWorking || s == kDone;
  }

  /// Decodes `message` on the caller's thread, now, as post() and collect() would (the pair's
  /// second image, wanted at once); a decode still posted is collected and discarded first.
  const cv::Mat* decode(std::shared_ptr<const stereograsp::image_t> message, cv::Rect region,
                        std::string* error);

  /// Until `until`, the worker polls for a post instead of sleeping (a later call moves it; a
  /// past time lets it sleep again). Cheap to call again and again: it wakes the worker only
  /// when it sleeps.
  void stay_awake_until(std::chrono::steady_clock::time_point until);

  /// Decodes collect() found done or under way by the worker, and those it did itself.
  uint64_t by_worker() const { return by_worker_; }
  uint64_t by_caller() const { return by_caller_; }

 private:
  enum State : int { kIdle, kPosted, kWorking, kDone };
  void run();                // the worker thread
  void run_decode();         // the posted message, on whichever thread took it
  void settle();             // collects (and discards) a decode still posted
  bool awake() const;        // before the time of stay_awake_until()
  void poll();               // the worker, awake: until a post, stop_ or that time
  void keep_off_this_cpu();  // the worker on any core but the caller's

  FrameDecoder decoder_;
  std::shared_ptr<const stereograsp::image_t> message_;
  cv::Rect region_;
  const cv::Mat* frame_ = nullptr;
  std::string error_;
  std::atomic<int> state_{kIdle};
  std::atomic<int64_t> awake_until_{0};  // steady_clock ticks; 0: sleep
  std::atomic<bool> sleeping_{false};    // the worker waits on posted_
  std::mutex mutex_;                     // the worker's sleep and stop_; not on the frame's path
  std::condition_variable posted_;
  std::atomic<bool> stop_{false};  // set under mutex_ (for the sleep's wake-up), read anywhere
  uint64_t by_worker_ = 0, by_caller_ = 0;
  std::thread thread_;  // last: starts once everything above exists
};

}  // namespace sg::vision
