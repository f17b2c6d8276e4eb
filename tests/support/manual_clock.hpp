#pragma once

// A clock that stands where the test puts it (utime() only; nothing that uses it waits).

#include <cstdint>
#include <functional>
#include <mutex>
#include <stop_token>

#include "common/clock.hpp"

namespace sg::test {

class ManualClock : public Clock {
 public:
  explicit ManualClock(int64_t start_utime) : at(start_utime) {}
  int64_t at;
  double now() override { return static_cast<double>(at) * 1e-6; }
  int64_t utime() override { return at; }
  bool wait_until(std::unique_lock<std::mutex>&, double, const std::function<bool()>& ready,
                  std::stop_token) override {
    return ready();
  }
  void notify() override {}
  void sleep_until(double) override {}
};

}  // namespace sg::test
