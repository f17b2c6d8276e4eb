// The wait helpers: a condition that comes true, one that never does, the failure's message, and
// a wait that handles a bus (memq://).

#include "tests/support/wait.hpp"

#include <gtest/gtest.h>

#include "common/bus.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// A condition true at its 5th check: wait_until returns true after exactly 5 checks, 4 polls apart.
TEST(WaitUntil, ReturnsOnceTheConditionHoldsAfterNPolls) {
  int checks = 0;
  const auto start = Clock::now();
  EXPECT_TRUE(wait_until([&] { return ++checks == 5; }, 60s, 10ms));
  EXPECT_EQ(checks, 5);
  EXPECT_GE(Clock::now() - start, 40ms);
  EXPECT_LT(Clock::now() - start, 30s)
      << "it returned when the condition held, not at the deadline";
}

// A condition already true is checked once and costs no poll.
TEST(WaitUntil, AConditionAlreadyTrueIsCheckedOnce) {
  int checks = 0;
  EXPECT_TRUE(wait_until([&] { return ++checks > 0; }, 10s, 1s));
  EXPECT_EQ(checks, 1);
}

// A condition that never holds: false, after the deadline and not much later (a slow machine is
// allowed a second), checked once more at the deadline.
TEST(WaitUntil, TimesOutNearTheDeadline) {
  int checks = 0;
  const auto start = Clock::now();
  EXPECT_FALSE(wait_until([&] { return ++checks < 0; }, 200ms, 10ms));
  const auto waited = Clock::now() - start;
  EXPECT_GE(waited, 200ms);
  EXPECT_LT(waited, 1200ms);
  EXPECT_GE(checks, 2);
  EXPECT_LE(checks, 22);
}

// A condition that comes true at the deadline counts as held, checked then and not one whole poll
// (500 ms) later.
TEST(WaitUntil, TheLastCheckIsAtTheDeadline) {
  const auto start = Clock::now();
  EXPECT_TRUE(wait_until([&] { return Clock::now() >= start + 100ms; }, 100ms, 500ms));
  EXPECT_LT(Clock::now() - start, 500ms);
}

// eventually() succeeds quietly, and on time-out says what it waited for and for how long.
TEST(Eventually, TheFailureSaysWhatItWaitedFor) {
  EXPECT_TRUE(eventually([] { return true; }, 1s, "nothing"));
  const ::testing::AssertionResult r = eventually([] { return false; }, 50ms, "the ball to land");
  EXPECT_FALSE(r);
  EXPECT_STREQ(r.message(), "timed out after 50 ms waiting for the ball to land");
}

// On a bus: a message this test publishes to itself arrives while eventually() handles the bus.
TEST(Eventually, HandlesTheBusWhileItWaits) {
  Bus bus("memq://");
  int arrived = 0;
  bus.subscribe_raw("PING", [&](const RawMessage&) { ++arrived; });
  const uint8_t byte = 1;
  bus.publish_raw("PING", &byte, 1);
  bus.publish_raw("PING", &byte, 1);
  EXPECT_TRUE(eventually(
      bus, [&] { return arrived == 2; }, 10s, "two PINGs"));
  const ::testing::AssertionResult r = eventually(
      bus, [&] { return arrived == 3; }, 50ms, "a third");
  EXPECT_FALSE(r);
  EXPECT_STREQ(r.message(), "timed out after 50 ms waiting for a third");
}

// handle_for() handles what arrives during the window and returns at its end.
TEST(HandleFor, HandlesMessagesForTheWholeWindow) {
  Bus bus("memq://");
  int arrived = 0;
  bus.subscribe_raw("PING", [&](const RawMessage&) { ++arrived; });
  const uint8_t byte = 1;
  bus.publish_raw("PING", &byte, 1);
  const auto start = Clock::now();
  handle_for(bus, 200ms);
  EXPECT_GE(Clock::now() - start, 200ms);
  EXPECT_EQ(arrived, 1);
}

}  // namespace
}  // namespace sg::test
