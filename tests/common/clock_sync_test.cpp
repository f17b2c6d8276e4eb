// NTP-style clock offsets from heartbeats: two simulated processes with known clocks and delays
// exchange statuses through ClockSync, and the offset each measures is checked against the truth.

#include "common/clock_sync.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

namespace sg {
namespace {

using stereograsp::process_status_t;

/// One process: its name, its clock's offset to true time (µs), and its ClockSync.
struct Host {
  Host(std::string program, std::string host, int32_t process_id, int64_t clock_offset)
      : status_name(std::move(program)),
        host_name(std::move(host)),
        pid(process_id),
        offset(clock_offset),
        sync(status_name + "@" + host_name + ":" + std::to_string(pid)) {}
  std::string status_name, host_name;
  int32_t pid;
  int64_t offset;
  ClockSync sync;

  int64_t clock(int64_t true_time) const { return true_time + offset; }
  /// The status it publishes at true time `t`.
  process_status_t publish(int64_t t) {
    process_status_t s{};
    s.utime = clock(t);
    s.process = status_name;
    s.host = host_name;
    s.pid = pid;
    sync.fill(s);
    return s;
  }
  void receive(const process_status_t& s, int64_t t) { sync.receive(s, clock(t)); }
};

/// Runs `beats` heartbeats of A and B, 1 s apart, B half a second after A; `out` and `back`
/// are the one-way delays A to B and B to A (µs).
void exchange(Host& a, Host& b, int beats, int64_t out, int64_t back) {
  int64_t t = 1'700'000'000'000'000;
  for (int k = 0; k < beats; ++k, t += 1'000'000) {
    const process_status_t from_a = a.publish(t);
    b.receive(from_a, t + out);
    const process_status_t from_b = b.publish(t + 500'000);
    a.receive(from_b, t + 500'000 + back);
  }
}

// Equal delays: the offset is exact, its bound half the round trip.
TEST(ClockSync, SymmetricDelaysGiveTheExactOffset) {
  Host a("sg-grasp", "lab2", 10, 0), b("sg-vision", "lab1", 20, 812'345);
  exchange(a, b, 3, 300, 300);
  const auto o = a.sync.offset("sg-vision@lab1:20");
  ASSERT_TRUE(o && o->known);
  EXPECT_EQ(o->offset_us, 812'345);
  EXPECT_EQ(o->error_us, 300);
  EXPECT_EQ(o->host, "lab1");
  const auto back = b.sync.offset("sg-grasp@lab2:10");
  ASSERT_TRUE(back && back->known);
  EXPECT_EQ(back->offset_us, -812'345);
}

// Unequal delays: the estimate is off by half their difference, and within its own bound.
TEST(ClockSync, AsymmetricDelaysStayWithinTheBound) {
  Host a("sg-grasp", "lab2", 10, -250'000), b("sg-vision", "lab1", 20, 1'000'000);
  exchange(a, b, 4, 100, 2100);
  const auto o = a.sync.offset("sg-vision@lab1:20");
  ASSERT_TRUE(o && o->known);
  const int64_t truth = 1'250'000;
  EXPECT_EQ(o->offset_us - truth, (100 - 2100) / 2);
  EXPECT_LE(std::abs(o->offset_us - truth), o->error_us);
}

// Of the last exchanges the one of least delay wins: one fast exchange among slow ones.
TEST(ClockSync, LeastDelayExchangeIsKept) {
  Host a("sg-grasp", "lab2", 10, 0), b("sg-vision", "lab1", 20, 5'000);
  exchange(a, b, 2, 100, 9000);  // slow and lopsided: 4450 µs off
  exchange(a, b, 1, 200, 200);   // fast and even: exact
  exchange(a, b, 2, 100, 9000);
  const auto o = a.sync.offset("sg-vision@lab1:20");
  ASSERT_TRUE(o && o->known);
  EXPECT_EQ(o->offset_us, 5'000);
  EXPECT_EQ(o->error_us, 200);
}

// A status heard once, before any of ours was echoed, gives no offset yet.
TEST(ClockSync, NoOffsetBeforeAnExchange) {
  Host a("sg-grasp", "lab2", 10, 0), b("sg-vision", "lab1", 20, 5'000);
  a.receive(b.publish(1'700'000'000'000'000), 1'700'000'000'000'100);
  const auto o = a.sync.offset("sg-vision@lab1:20");
  ASSERT_TRUE(o);
  EXPECT_FALSE(o->known);
  EXPECT_EQ(o->error_us, -1);
  process_status_t mine{};
  mine.utime = 1'700'000'000'500'000;
  a.sync.fill(mine);
  ASSERT_EQ(mine.num_peers, 1);
  EXPECT_EQ(mine.peer[0], "sg-vision@lab1:20");
  EXPECT_EQ(mine.peer_offset_error_us[0], -1);
}

// An echo of a time we never sent, a negative delay, and times at the int64 limits are ignored.
TEST(ClockSync, MadeUpEchoesAreIgnored) {
  Host a("sg-grasp", "lab2", 10, 0);
  a.publish(1'000'000);  // our one status: t1 = 1 s
  process_status_t forged{};
  forged.process = "sg-vision";
  forged.host = "lab1";
  forged.pid = 20;
  forged.utime = std::numeric_limits<int64_t>::max();
  forged.num_peers = 1;
  forged.peer = {"sg-grasp@lab2:10"};
  forged.peer_recv_utime = {std::numeric_limits<int64_t>::min()};
  forged.peer_offset_us = {0};
  forged.peer_offset_error_us = {0};
  forged.peer_utime = {999};  // not ours
  a.sync.receive(forged, 2'000'000);
  forged.peer_utime = {1'000'000};  // ours, but the times overflow
  a.sync.receive(forged, 2'000'000);
  forged.utime = 1'500'000, forged.peer_recv_utime = {1'400'000};  // held 0.1 s ...
  a.sync.receive(forged, 1'050'000);  // ... in a round trip of 0.05 s: a negative delay
  EXPECT_EQ(a.sync.ignored(), 3u);
  EXPECT_FALSE(a.sync.offset("sg-vision@lab1:20")->known);
}

// However many names a hostile host invents, the table holds kMaxPeers, the newest heard.
TEST(ClockSync, PeerTableIsBounded) {
  ClockSync sync("sg-grasp@lab2:10");
  for (int i = 0; i < 1000; ++i) {
    process_status_t s{};
    s.process = std::string("x");  // (a literal assigned trips GCC 12's -Wrestrict here)
    s.host = std::string("h");
    s.pid = i;
    s.utime = i;
    sync.receive(s, 1'000'000 + i);
  }
  const auto all = sync.offsets();
  ASSERT_EQ(all.size(), ClockSync::kMaxPeers);
  EXPECT_EQ(all.back().peer, "x@h:999");
  process_status_t mine{};
  mine.utime = 1'001'000;
  sync.fill(mine);
  EXPECT_EQ(mine.num_peers, static_cast<int32_t>(ClockSync::kMaxPeers));
}

// Our own status, looped back by LCM, is not a peer.
TEST(ClockSync, OwnStatusIsNotAPeer) {
  Host a("sg-grasp", "lab2", 10, 0);
  a.receive(a.publish(1'000'000), 1'000'100);
  EXPECT_TRUE(a.sync.offsets().empty());
}

}  // namespace
}  // namespace sg
