// The line faults of sg-c550-sim: none at rate 0, all at rate 1, the same ones for one seed.

#include "sim/fault_injector.hpp"

#include <gtest/gtest.h>

namespace sg::sim {
namespace {

C550Emulator::Chunk chunk(std::vector<uint8_t> bytes, bool ack = false) { return {bytes, ack}; }

std::vector<uint8_t> through(FaultInjector& faults, const std::vector<C550Emulator::Chunk>& in) {
  std::deque<uint8_t> out;
  for (const auto& c : in) faults.apply(c, out);
  return {out.begin(), out.end()};
}

// At rate 0 every byte passes unchanged and every ACK arrives.
TEST(FaultInjector, RateZeroChangesNothing) {
  FaultInjector faults(0, 0, 7);
  EXPECT_EQ(through(faults, {chunk({1, 2, 3}), chunk({0x06}, true)}),
            (std::vector<uint8_t>{1, 2, 3, 0x06}));
  EXPECT_EQ(faults.garbled(), 0);
  EXPECT_EQ(faults.dropped(), 0);
}

// At garble rate 1 every byte is replaced by a different value; at drop rate 1 every ACK is lost
// but other chunks pass.
TEST(FaultInjector, RateOneGarblesEveryByteAndDropsEveryAck) {
  FaultInjector garble(1, 0, 7);
  const std::vector<uint8_t> sent = {0, 1, 0x7f, 0xff, 0x06};
  const auto got = through(garble, {chunk(sent)});
  ASSERT_EQ(got.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) EXPECT_NE(got[i], sent[i]) << i;
  EXPECT_EQ(garble.garbled(), 5);
  FaultInjector drop(0, 1, 7);
  EXPECT_EQ(through(drop, {chunk({0x06}, true), chunk({9, 9}), chunk({0x06}, true)}),
            (std::vector<uint8_t>{9, 9}));
  EXPECT_EQ(drop.dropped(), 2);
}

// One seed gives the same faults every time; the rate is kept over many bytes.
TEST(FaultInjector, FixedSeedRepeatsItsFaults) {
  std::vector<C550Emulator::Chunk> in;
  for (int i = 0; i < 2000; ++i) in.push_back(chunk({static_cast<uint8_t>(i), 0x0d}, i % 2 == 0));
  FaultInjector a(0.05, 0.2, 42), b(0.05, 0.2, 42), c(0.05, 0.2, 43);
  const auto out_a = through(a, in);
  EXPECT_EQ(out_a, through(b, in));
  EXPECT_NE(out_a, through(c, in));
  EXPECT_EQ(a.garbled(), b.garbled());
  EXPECT_EQ(a.dropped(), b.dropped());
  // 1000 ACK chunks at 0.2: about 200 dropped; ~3,600 bytes sent at 0.05: about 180 garbled.
  EXPECT_NEAR(static_cast<double>(a.dropped()), 200, 50);
  EXPECT_NEAR(static_cast<double>(a.garbled()), 0.05 * (4000 - 2 * a.dropped()), 50);
}

}  // namespace
}  // namespace sg::sim
