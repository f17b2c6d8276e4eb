#include "system/simulated_clock.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace sg::system {
namespace {

// Events run in time order, and in scheduling order at the same time.
TEST(SimulatedClock, RunsEventsInTimeThenSchedulingOrder) {
  SimulatedClock clock(0);
  std::vector<int> order;
  clock.at(2.0, [&](double) { order.push_back(3); });
  clock.at(1.0, [&](double) { order.push_back(1); });
  clock.at(1.0, [&](double) { order.push_back(2); });
  clock.sleep_until(5.0);
  EXPECT_EQ(order, (std::vector<int>{1, 2, 3}));
  EXPECT_DOUBLE_EQ(clock.now(), 5.0);
}

// A periodic event runs at first + k * period exactly: no rounding drift after 10,000 runs.
TEST(SimulatedClock, PeriodicEventsDoNotDrift) {
  SimulatedClock clock(0);
  std::vector<double> times;
  clock.every(0.1, [&](double t) { times.push_back(t); }, 0.05);
  clock.sleep_until(1000.0);
  ASSERT_EQ(times.size(), 10000u);
  EXPECT_DOUBLE_EQ(times.back(), 0.05 + 9999 * 0.1);
}

// wait_until returns as soon as an event makes the condition true, at that event's time.
TEST(SimulatedClock, WaitEndsWhenAnEventMakesTheConditionTrue) {
  SimulatedClock clock(0);
  std::mutex m;
  bool ready = false;
  clock.at(0.7, [&](double) {
    std::lock_guard lock(m);  // the waiter's lock is free while events run
    ready = true;
  });
  clock.at(0.9, [&](double) { ADD_FAILURE() << "ran past the condition"; });
  std::unique_lock lock(m);
  EXPECT_TRUE(clock.wait_until(lock, 10.0, [&] { return ready; }));
  EXPECT_DOUBLE_EQ(clock.now(), 0.7);
}

// A condition that never holds returns false at the deadline, the later events still pending.
TEST(SimulatedClock, WaitTimesOutAtTheDeadline) {
  SimulatedClock clock(1'000'000);
  int runs = 0;
  clock.every(1.0, [&](double) { ++runs; });
  std::mutex m;
  std::unique_lock lock(m);
  EXPECT_FALSE(clock.wait_until(lock, 3.5, [] { return false; }));
  EXPECT_DOUBLE_EQ(clock.now(), 3.5);
  EXPECT_EQ(runs, 4);  // t = 0, 1, 2, 3
  EXPECT_DOUBLE_EQ(clock.next_event_time(), 4.0);
  EXPECT_EQ(clock.utime(), 1'000'000 + 3'500'000);
}

// A stop requested by an event ends the wait at once.
TEST(SimulatedClock, StopEndsTheWait) {
  SimulatedClock clock(0);
  std::stop_source stop;
  clock.at(2.0, [&](double) { stop.request_stop(); });
  std::mutex m;
  std::unique_lock lock(m);
  EXPECT_FALSE(clock.wait_until(lock, 100.0, [] { return false; }, stop.get_token()));
  EXPECT_DOUBLE_EQ(clock.now(), 2.0);
}

// utime and time convert both ways around the epoch.
TEST(SimulatedClock, ConvertsBetweenSecondsAndUtime) {
  SimulatedClock clock(1'700'000'000'000'000);
  EXPECT_EQ(clock.utime_at(1.25), 1'700'000'001'250'000);
  EXPECT_DOUBLE_EQ(clock.time_of(1'700'000'001'250'000), 1.25);
}

}  // namespace
}  // namespace sg::system
