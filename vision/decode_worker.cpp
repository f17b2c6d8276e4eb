#include "vision/decode_worker.hpp"

#include <pthread.h>
#include <sched.h>

namespace sg::vision {

DecodeWorker::DecodeWorker(FrameDecoder::Mode mode) : decoder_(mode), thread_([this] { run(); }) {}

DecodeWorker::~DecodeWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  posted_.notify_one();
  thread_.join();
}

void DecodeWorker::run_decode() {
  error_.clear();
  frame_ = decoder_.decode(*message_, region_, &error_);
}

void DecodeWorker::keep_off_this_cpu() {
  cpu_set_t others;  // the cores this (the caller's) thread may use, but the one it is on
  const int here = sched_getcpu();
  if (here < 0 || here >= CPU_SETSIZE || sched_getaffinity(0, sizeof others, &others) != 0) return;
  CPU_CLR(here, &others);
  if (CPU_COUNT(&others) == 0) return;  // one core: nowhere else to go
  pthread_setaffinity_np(thread_.native_handle(), sizeof others, &others);  // a hint: may fail
}

bool DecodeWorker::awake() const {
  return std::chrono::steady_clock::now().time_since_epoch().count() < awake_until_.load();
}

void DecodeWorker::poll() {
  while (state_.load(std::memory_order_acquire) != kPosted && awake() && !stop_.load())
    std::this_thread::yield();  // no lock: post() takes mutex_, and this runs 1000s of times
}

void DecodeWorker::run() {
  for (;;) {
    poll();
    {
      std::unique_lock<std::mutex> lock(mutex_);
      sleeping_.store(true);
      posted_.wait(lock, [&] { return stop_ || state_.load() == kPosted || awake(); });
      sleeping_.store(false);
      if (stop_) return;
      if (state_.load() != kPosted) continue;  // awake again: poll
    }
    int expected = kPosted;
    if (!state_.compare_exchange_strong(expected, kWorking, std::memory_order_acquire))
      continue;  // the caller took it
    run_decode();
    state_.store(kDone, std::memory_order_release);
  }
}

void DecodeWorker::stay_awake_until(std::chrono::steady_clock::time_point until) {
  awake_until_.store(until.time_since_epoch().count());  // seq_cst with sleeping_
  if (!sleeping_.load() || !awake()) return;
  keep_off_this_cpu();
  std::lock_guard<std::mutex> lock(mutex_);  // so the worker cannot miss the change
  posted_.notify_one();
}

void DecodeWorker::settle() {
  if (state_.load(std::memory_order_acquire) == kIdle) return;
  std::string ignored;
  collect(&ignored);  // the decoder is one: the last decode ends before the next begins
}

const cv::Mat* DecodeWorker::decode(std::shared_ptr<const stereograsp::image_t> message,
                                    cv::Rect region, std::string* error) {
  settle();
  message_ = std::move(message);
  region_ = region;
  run_decode();
  if (frame_ == nullptr && error) *error = error_;
  return frame_;
}

void DecodeWorker::post(std::shared_ptr<const stereograsp::image_t> message, cv::Rect region) {
  settle();
  message_ = std::move(message);
  region_ = region;
  {
    std::lock_guard<std::mutex> lock(mutex_);  // so the worker cannot miss the change
    state_.store(kPosted, std::memory_order_release);
  }
  posted_.notify_one();
}

const cv::Mat* DecodeWorker::collect(std::string* error) {
  int expected = kPosted;
  if (state_.compare_exchange_strong(expected, kWorking, std::memory_order_acquire)) {
    run_decode();  // the worker has not begun: in line, as without it
    ++by_caller_;
  } else if (expected != kIdle) {  // kIdle: collected already
    // Under way or done: a decode takes a fraction of a millisecond, so spin (yielding the core)
    // rather than sleep and wait for a wake-up.
    while (state_.load(std::memory_order_acquire) != kDone) std::this_thread::yield();
    ++by_worker_;
  }
  if (!message_) {
    if (error) *error = "nothing was posted";
    return nullptr;
  }
  state_.store(kIdle, std::memory_order_relaxed);
  if (frame_ == nullptr && error) *error = error_;
  return frame_;
}

}  // namespace sg::vision
