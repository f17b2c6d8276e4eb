// A bus with a guard (common/bus.hpp, auth/data_auth.hpp) over memq://: what it publishes is
// vouched for and what it believes reaches every subscription once, decoded without the trailer;
// what nobody vouched for never reaches a handler and is counted per channel, sender and verdict
// on PROCESS_STATUS; a bus without a guard reads vouched messages as plain ones.

#include <gtest/gtest.h>

#include "auth/data_auth.hpp"
#include "common/bus.hpp"
#include "common/message_types.hpp"

namespace sg::auth {
namespace {

using namespace std::chrono_literals;

LabKey test_key() {
  std::array<uint8_t, LabKey::kSize> b{};
  b.fill(0x42);
  return LabKey(b);
}

/// A lab of one process "a" that publishes on OBJECT_POSITION and reads it.
std::shared_ptr<DataGuard> guard_of(const std::string& identity) {
  const ChannelRights rights = {{"OBJECT_POSITION", {"a"}, {"a"}},
                                {"PROCESS_STATUS", {"a"}, {"a"}}};
  return std::make_shared<DataGuard>(credentials_from_lab_key(test_key(), identity, rights));
}

stereograsp::point3_t point(int64_t utime) {
  stereograsp::point3_t p{};
  p.utime = utime;
  p.visible = 1;
  p.position[0] = 0.5;
  return p;
}

/// Encoded bytes of `m`, as a rogue publisher would send them.
template <class M>
std::vector<uint8_t> bytes_of(const M& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// A vouched message reaches both subscriptions on its channel, decoded; nothing is refused (a
// second check of the same message would have called it a replay).
TEST(BusGuard, VouchedMessageReachesEverySubscriptionOnce) {
  Bus bus("memq://");
  bus.set_guard(guard_of("a"));
  int first = 0, second = 0;
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION", [&](const auto& p, const auto& info) {
    first += p.utime == 7 && info.size == point(7).getEncodedSize();
  });
  bus.subscribe<stereograsp::point3_t>("OBJECT_.*",
                                       [&](const auto& p, const auto&) { second += p.utime == 7; });
  bus.publish("OBJECT_POSITION", point(7));
  while (bus.handle(10ms)) {
  }
  EXPECT_EQ(first, 1);
  EXPECT_EQ(second, 1);
  EXPECT_EQ(bus.unvouched_inputs(), 0u);
  EXPECT_EQ(bus.decode_errors(), 0u);
}

// Two messages handed to the same subscriptions one after the other are judged each on its own:
// a forged one right after a vouched one, of the same size and trailer, reaches no handler.
TEST(BusGuard, EachMessageIsJudgedOnItsOwn) {
  Bus bus("memq://");
  bus.set_guard(guard_of("a"));
  int first = 0, second = 0;
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION",
                                       [&](const auto& p, const auto&) { first += p.utime; });
  bus.subscribe<stereograsp::point3_t>("OBJECT_.*",
                                       [&](const auto& p, const auto&) { second += p.utime; });
  std::vector<uint8_t> vouched = bytes_of(point(1));
  guard_of("a")->vouch("OBJECT_POSITION", vouched);
  std::vector<uint8_t> forged = bytes_of(point(100));  // the same size, the same trailer
  forged.insert(forged.end(), vouched.begin() + static_cast<long>(forged.size()), vouched.end());
  ASSERT_EQ(forged.size(), vouched.size());
  bus.lcm().publish("OBJECT_POSITION", vouched.data(), vouched.size());
  bus.lcm().publish("OBJECT_POSITION", forged.data(), forged.size());
  while (bus.handle(10ms)) {
  }
  EXPECT_EQ(first, 1);
  EXPECT_EQ(second, 1);
  EXPECT_EQ(bus.unvouched().at({"OBJECT_POSITION", "a", GuardVerdict::kBadTag}), 1u);
  // The same through a caller's own lcm().handle(), which shares no verdict: the forged one still
  // reaches no handler (the vouched one reaches the first subscription; the second, judging it
  // again, calls it a replay: it refuses, it never believes).
  std::vector<uint8_t> again = bytes_of(point(2));
  guard_of("a")->vouch("OBJECT_POSITION", again);
  bus.lcm().publish("OBJECT_POSITION", again.data(), again.size());
  bus.lcm().publish("OBJECT_POSITION", forged.data(), forged.size());
  bus.lcm().handle();
  bus.lcm().handle();
  EXPECT_EQ(first, 3);
  EXPECT_EQ(second, 1);
  EXPECT_EQ(bus.unvouched().at({"OBJECT_POSITION", "a", GuardVerdict::kBadTag}), 3u);  // twice
  EXPECT_EQ(bus.unvouched().at({"OBJECT_POSITION", "a", GuardVerdict::kReplayed}), 1u);
}

// Unsigned bytes and bytes vouched for by a process not allowed on the channel never reach the
// handler; each is counted under its channel, claimed sender and verdict, and PROCESS_STATUS
// carries the rows and who the bus vouches as.
TEST(BusGuard, UnvouchedMessagesAreCountedAndNeverHandled) {
  Bus bus("memq://");
  bus.set_guard(guard_of("a"));
  int handled = 0;
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION",
                                       [&](const auto&, const auto&) { ++handled; });
  std::vector<uint8_t> plain = bytes_of(point(1));
  for (int i = 0; i < 3; ++i) bus.lcm().publish("OBJECT_POSITION", plain.data(), plain.size());
  std::vector<uint8_t> stranger = bytes_of(point(2));
  guard_of("b")->vouch("OBJECT_POSITION", stranger);  // a lab key's holder, but not allowed
  bus.lcm().publish("OBJECT_POSITION", stranger.data(), stranger.size());
  while (bus.handle(10ms)) {
  }
  EXPECT_EQ(handled, 0);
  EXPECT_EQ(bus.unvouched_inputs(), 4u);
  using Key = Bus::UnvouchedKey;
  EXPECT_EQ(bus.unvouched().at(Key{"OBJECT_POSITION", "", GuardVerdict::kUnsigned}), 3u);
  EXPECT_EQ(bus.unvouched().at(Key{"OBJECT_POSITION", "b", GuardVerdict::kNotAllowed}), 1u);
  const stereograsp::process_status_t s = bus.process_status(1);
  EXPECT_EQ(s.unvouched_inputs, 4);
  ASSERT_EQ(s.num_unvouched, 2);
  EXPECT_EQ(s.unvouched_channel[0], "OBJECT_POSITION");
  EXPECT_EQ(s.unvouched_verdict[0], "unsigned");
  EXPECT_EQ(s.unvouched_count[0], 3);
  EXPECT_EQ(s.unvouched_sender[1], "b");
  EXPECT_EQ(s.unvouched_verdict[1], "not allowed");
  EXPECT_EQ(s.vouched_as, "a");
  EXPECT_NE(bus.last_problem().find("not vouched for (not allowed)"), std::string::npos)
      << bus.last_problem();
}

// A bus without a guard takes a well-formed trailer off and decodes the message as it was sent.
TEST(BusGuard, UnguardedBusReadsVouchedMessages) {
  Bus bus("memq://");
  int handled = 0;
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION", [&](const auto& p, const auto&) {
    handled += p.utime == 3 && p.position[0] == 0.5;
  });
  std::vector<uint8_t> vouched = bytes_of(point(3));
  guard_of("a")->vouch("OBJECT_POSITION", vouched);
  bus.lcm().publish("OBJECT_POSITION", vouched.data(), vouched.size());
  while (bus.handle(10ms)) {
  }
  EXPECT_EQ(handled, 1);
  EXPECT_EQ(bus.decode_errors(), 0u);
  EXPECT_EQ(bus.process_status(1).vouched_as, "");
}

// A PROCESS_STATUS nobody the lab allows vouched for never reaches the clock exchange: the clock
// offsets a process measures (and sg-grasp corrects its timing by) come only from vouched peers.
TEST(BusGuard, ForgedStatusesNeverReachTheClockExchange) {
  Bus bus("memq://");
  bus.set_guard(guard_of("a"));
  bus.announce("a");
  stereograsp::process_status_t forged{};
  forged.utime = now_utime() + 5'000'000;  // a host 5 s ahead, it would claim
  forged.process = "a";
  forged.host = "elsewhere";
  forged.pid = 4242;
  std::vector<uint8_t> unsigned_bytes = bytes_of(forged), stranger_bytes = bytes_of(forged);
  guard_of("b")->vouch("PROCESS_STATUS", stranger_bytes);
  std::vector<uint8_t> vouched = bytes_of(forged);
  guard_of("a")->vouch("PROCESS_STATUS", vouched);
  bus.lcm().publish("PROCESS_STATUS", unsigned_bytes.data(), unsigned_bytes.size());
  bus.lcm().publish("PROCESS_STATUS", stranger_bytes.data(), stranger_bytes.size());
  while (bus.handle(10ms)) {
  }
  ASSERT_NE(bus.clock_sync(), nullptr);
  EXPECT_TRUE(bus.clock_sync()->offsets().empty()) << "a forged peer was heard";
  EXPECT_EQ(bus.unvouched().at({"PROCESS_STATUS", "", GuardVerdict::kUnsigned}), 1u);
  EXPECT_EQ(bus.unvouched().at({"PROCESS_STATUS", "b", GuardVerdict::kNotAllowed}), 1u);
  // The same status vouched for by an allowed publisher is heard (the check is what kept it out).
  bus.lcm().publish("PROCESS_STATUS", vouched.data(), vouched.size());
  while (bus.handle(10ms)) {
  }
  ASSERT_EQ(bus.clock_sync()->offsets().size(), 1u);
  EXPECT_EQ(bus.clock_sync()->offsets()[0].host, "elsewhere");
}

// The refusal table is bounded: 100 made-up senders give at most 32 rows and an "(other)" row
// that sums the rest.
TEST(BusGuard, RefusalRowsAreBounded) {
  Bus bus("memq://");
  bus.set_guard(guard_of("a"));
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION", [&](const auto&, const auto&) {});
  for (int i = 0; i < 100; ++i) {
    std::vector<uint8_t> m = bytes_of(point(i));
    guard_of("rogue" + std::to_string(i))->vouch("OBJECT_POSITION", m);
    bus.lcm().publish("OBJECT_POSITION", m.data(), m.size());
    while (bus.handle(1ms)) {
    }
  }
  EXPECT_EQ(bus.unvouched().size(), Bus::kUnvouchedRows + 1);
  uint64_t total = 0;
  for (const auto& [key, n] : bus.unvouched()) total += n;
  EXPECT_EQ(total, 100u);
  EXPECT_EQ(bus.process_status(1).num_unvouched, 33);
}

}  // namespace
}  // namespace sg::auth
