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
/// Lifecycle: the thread starts with the object and is joined by its destructor (after the decode
/// under way, if any). post() and collect() are for one thread, the owner's; the frame collect()
/// returns stays valid until the next post().

#include <atomic>
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

  /// Decodes collect() found done or under way by the worker, and those it did itself.
  uint64_t by_worker() const { return by_worker_; }
  uint64_t by_caller() const { return by_caller_; }

 private:
  enum State : int { kIdle, kPosted, kWorking, kDone };
  void run();         // the worker thread
  void run_decode();  // the posted message, on whichever thread took it
  void settle();      // collects (and discards) a decode still posted

  FrameDecoder decoder_;
  std::shared_ptr<const stereograsp::image_t> message_;
  cv::Rect region_;
  const cv::Mat* frame_ = nullptr;
  std::string error_;
  std::atomic<int> state_{kIdle};
  std::mutex mutex_;  // the worker's sleep and stop_; not on the frame's path
  std::condition_variable posted_;
  bool stop_ = false;
  uint64_t by_worker_ = 0, by_caller_ = 0;
  std::thread thread_;  // last: starts once everything above exists
};

}  // namespace sg::vision
