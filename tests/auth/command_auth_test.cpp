// Signed commands (auth/command_auth.hpp): round trips of both types, and 10,000 each of forged,
// replayed, unsigned, other-channel, modified and wrong-key commands with none accepted; the
// forged STOP that once locked sg-grasp out; stale counters; a bounded sender table.

#include "auth/command_auth.hpp"

#include <gtest/gtest.h>
#include <sodium.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>

#include "arm_driver/arm_driver.hpp"
#include "tests/support/arm_commands.hpp"
#include "tests/support/manual_clock.hpp"

namespace sg::auth {
namespace {

using stereograsp::arm_cmd_t;
using stereograsp::grasp_command_t;

constexpr int kTrials = 10'000;
constexpr int64_t kT0 = 1'780'000'000'000'000;  // µs since the epoch (2026)

/// The test's clock, at kT0 unless moved.
struct ManualClock : test::ManualClock {
  ManualClock() : test::ManualClock(kT0) {}
};

LabKey key_from(uint8_t seed) {
  std::array<uint8_t, LabKey::kSize> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(seed + 7 * i);
  return LabKey(bytes);
}

/// A reachable tool-down move (the driver accepts it).
arm_cmd_t move(int64_t sequence) {
  arm_cmd_t c =
      test::tool_down_move(sequence, 0.45, 0.10, 0.30, std::atan2(0.10, 0.45) + std::numbers::pi);
  c.utime = kT0;
  return c;
}

grasp_command_t grasp(int64_t sequence) {
  grasp_command_t c{};
  c.utime = kT0;
  c.sequence = sequence;
  c.command = grasp_command_t::COMMAND_GRASP;
  c.standoff = 0.1;
  return c;
}

template <class M>
std::vector<uint8_t> bytes_of(const M& m) {
  std::vector<uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

template <class M>
M decoded(const std::vector<uint8_t>& b) {
  M m{};
  EXPECT_EQ(m.decode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return m;
}

struct Fixture : ::testing::Test {
  LabKey key = key_from(1);
  ManualClock clock;
  CommandSigner signer{key, "sg-grasp", clock};
  CommandVerifier verifier{key};
};
using CommandAuth = Fixture;

// An arm command signed on ARM_COMMAND carries sender, counter and a tag, and is accepted once.
TEST_F(CommandAuth, ArmCommandRoundTrip) {
  arm_cmd_t c = move(5);
  signer.sign("ARM_COMMAND", c);
  EXPECT_EQ(c.sender, "sg-grasp");
  EXPECT_EQ(c.auth_counter, kT0);
  EXPECT_FALSE(sodium_is_zero(c.auth_tag, kTagSize));
  EXPECT_EQ(command_tag(key, "ARM_COMMAND", c),
            std::to_array(c.auth_tag));  // the documented construction
  const arm_cmd_t received = decoded<arm_cmd_t>(bytes_of(c));
  const Verification v = verifier.verify("ARM_COMMAND", received, kT0 + 1000);
  EXPECT_TRUE(v.accepted()) << v.reason;
  EXPECT_EQ(v.reason, "");
  EXPECT_EQ(verifier.count(Verdict::kAccepted), 1);
  EXPECT_EQ(verifier.senders(), 1u);
}

// A grasp command round trip; the counter never repeats, even with the clock standing still.
TEST_F(CommandAuth, GraspCommandRoundTripAndIncreasingCounter) {
  for (int i = 0; i < 3; ++i) {
    grasp_command_t c = grasp(10);  // a resend: the same sequence, a new counter
    signer.sign("GRASP_COMMAND", c);
    EXPECT_EQ(c.auth_counter, kT0 + i);
    const Verification v = verifier.verify("GRASP_COMMAND", c, kT0);
    EXPECT_TRUE(v.accepted()) << v.reason;
  }
  clock.at = kT0 + 5'000'000;  // the clock moves on: the counter follows it
  grasp_command_t c = grasp(11);
  signer.sign("GRASP_COMMAND", c);
  EXPECT_EQ(c.auth_counter, kT0 + 5'000'000);
  clock.at = kT0;  // and a clock stepped back cannot take it back
  signer.sign("GRASP_COMMAND", c);
  EXPECT_EQ(c.auth_counter, kT0 + 5'000'001);
}

// 10,000 commands with random tags: none accepted, each a bad tag, and the sender table empty.
TEST_F(CommandAuth, ForgedTagsAreRefused) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < kTrials; ++i) {
    arm_cmd_t c = move(i + 1);
    c.sender = "sg-grasp";
    c.auth_counter = kT0 + i;
    for (auto& b : c.auth_tag) b = static_cast<uint8_t>(rng() | 1);  // never all zero
    EXPECT_EQ(verifier.verify("ARM_COMMAND", c, kT0).verdict, Verdict::kBadTag);
  }
  EXPECT_EQ(verifier.count(Verdict::kAccepted), 0);
  EXPECT_EQ(verifier.count(Verdict::kBadTag), kTrials);
  EXPECT_EQ(verifier.senders(), 0u);
}

// The same signed bytes sent again 10,000 times: accepted once, then every copy a replay.
TEST_F(CommandAuth, ReplayedBytesAreRefused) {
  arm_cmd_t c = move(1);
  signer.sign("ARM_COMMAND", c);
  const std::vector<uint8_t> wire = bytes_of(c);
  EXPECT_TRUE(verifier.verify("ARM_COMMAND", decoded<arm_cmd_t>(wire), kT0).accepted());
  for (int i = 0; i < kTrials; ++i) {
    const Verification v = verifier.verify("ARM_COMMAND", decoded<arm_cmd_t>(wire), kT0 + i);
    ASSERT_EQ(v.verdict, Verdict::kReplayed);
    if (i == 0) {
      EXPECT_EQ(v.reason, "replayed: auth_counter " + std::to_string(kT0) +
                              " from 'sg-grasp' not newer than its last accepted " +
                              std::to_string(kT0));
    }
  }
  // An older genuine command replayed after a newer one: refused too.
  arm_cmd_t older = move(2), newer = move(3);
  signer.sign("ARM_COMMAND", older);
  signer.sign("ARM_COMMAND", newer);
  EXPECT_TRUE(verifier.verify("ARM_COMMAND", newer, kT0).accepted());
  EXPECT_EQ(verifier.verify("ARM_COMMAND", older, kT0).verdict, Verdict::kReplayed);
  EXPECT_EQ(verifier.count(Verdict::kAccepted), 2);
  EXPECT_EQ(verifier.count(Verdict::kReplayed), kTrials + 1);
}

// 10,000 unsigned commands (a zero tag), whatever their counter: each refused as unsigned.
TEST_F(CommandAuth, UnsignedCommandsAreRefused) {
  for (int i = 0; i < kTrials; ++i) {
    grasp_command_t c = grasp(i);
    c.sender = "sg-grasp-ctl";
    c.auth_counter = kT0 + i;
    const Verification v = verifier.verify("GRASP_COMMAND", c, kT0);
    ASSERT_EQ(v.verdict, Verdict::kUnsigned);
    if (i == 0) {
      EXPECT_EQ(v.reason, "unsigned command from 'sg-grasp-ctl' (no auth_tag)");
    }
  }
  EXPECT_EQ(verifier.count(Verdict::kAccepted), 0);
  EXPECT_EQ(verifier.count(Verdict::kUnsigned), kTrials);
}

// 10,000 tags made for another channel (and one of the other type's channel): all bad tags.
TEST_F(CommandAuth, TagsFromAnotherChannelAreRefused) {
  for (int i = 0; i < kTrials; ++i) {
    arm_cmd_t c = move(i + 1);
    signer.sign(i % 2 ? "ARM_COMMAND_TEST" : "GRASP_COMMAND", c);
    ASSERT_EQ(verifier.verify("ARM_COMMAND", c, kT0).verdict, Verdict::kBadTag);
  }
  // The channel is length-prefixed: "ARM_COMMAN" + "D..." cannot be shifted into the message.
  arm_cmd_t c = move(1);
  signer.sign("ARM_COMMAN", c);
  EXPECT_EQ(verifier.verify("ARM_COMMAND", c, kT0).verdict, Verdict::kBadTag);
  EXPECT_EQ(verifier.count(Verdict::kAccepted), 0);
}

// 10,000 signed commands each changed in one field after signing: all bad tags.
TEST_F(CommandAuth, FieldsChangedAfterSigningAreRefused) {
  std::mt19937_64 rng(2);
  for (int i = 0; i < kTrials; ++i) {
    arm_cmd_t c = move(i + 1);
    signer.sign("ARM_COMMAND", c);
    switch (i % 9) {
      case 0:
        c.position[rng() % 3] += 0.01;
        break;
      case 1:
        c.sequence = std::numeric_limits<int64_t>::max();
        break;
      case 2:
        c.mode = arm_cmd_t::MODE_STOP;
        break;
      case 3:
        c.gripper = arm_cmd_t::GRIPPER_OPEN;
        break;
      case 4:
        c.speed = 1.0;
        break;
      case 5:
        c.sender = "sg-arm-ctl";
        break;
      case 6:
        c.auth_counter += 1;
        break;
      case 7:
        c.utime += 1;
        break;
      case 8:
        c.auth_tag[rng() % kTagSize] ^= static_cast<uint8_t>(1u << (rng() % 8));
        break;
    }
    ASSERT_EQ(verifier.verify("ARM_COMMAND", c, kT0).verdict, Verdict::kBadTag) << i % 9;
  }
  EXPECT_EQ(verifier.count(Verdict::kAccepted), 0);
}

// 10,000 commands signed with another key: all bad tags.
TEST_F(CommandAuth, WrongKeyIsRefused) {
  CommandSigner stranger(key_from(2), "sg-grasp", clock);
  for (int i = 0; i < kTrials; ++i) {
    grasp_command_t c = grasp(i + 1);
    stranger.sign("GRASP_COMMAND", c);
    ASSERT_EQ(verifier.verify("GRASP_COMMAND", c, kT0).verdict, Verdict::kBadTag);
  }
  EXPECT_EQ(verifier.count(Verdict::kAccepted), 0);
  EXPECT_EQ(verifier.count(Verdict::kBadTag), kTrials);
}

// Issue 15: a forged STOP with sequence 2^63-1 and sender sg-grasp (the highest counter too) is
// refused, and the real sg-grasp's next command is accepted by the verifier and by the driver,
// whose sequence bookkeeping the refusal left alone.
TEST_F(CommandAuth, ForgedStopDoesNotLockOutTheSender) {
  arm_cmd_t forged{};
  forged.sequence = std::numeric_limits<int64_t>::max();
  forged.mode = arm_cmd_t::MODE_STOP;
  forged.speed = 0.5;
  forged.sender = "sg-grasp";
  forged.auth_counter = std::numeric_limits<int64_t>::max();
  std::memset(forged.auth_tag, 0xa5, kTagSize);
  const Verification refused = verifier.verify("ARM_COMMAND", forged, kT0);
  EXPECT_EQ(refused.verdict, Verdict::kBadTag);

  arm::ArmDriver driver(arm::ArmGeometry::a465(), {}, [] { return nullptr; });
  driver.refuse(forged, "unauthenticated: " + refused.reason);
  EXPECT_EQ(driver.status().first.last_rejected_sequence, std::numeric_limits<int64_t>::max());
  EXPECT_EQ(driver.status().first.last_received_sequence, -1);
  EXPECT_EQ(driver.status().first.rejection_reason.rfind("unauthenticated: bad auth_tag", 0), 0u);

  arm_cmd_t real = move(7);
  signer.sign("ARM_COMMAND", real);
  EXPECT_TRUE(verifier.verify("ARM_COMMAND", real, kT0).accepted());
  driver.submit(real);
  EXPECT_EQ(driver.status().first.last_received_sequence, 7);
  EXPECT_EQ(driver.status().first.last_rejected_sequence, std::numeric_limits<int64_t>::max());
}

// A genuine command older than max_age (30 s) is stale, with the reason naming clock skew; one
// from a clock more than 30 s ahead is stale too; within the window it is accepted.
TEST_F(CommandAuth, StaleCountersAreRefused) {
  arm_cmd_t old = move(1);
  signer.sign("ARM_COMMAND", old);
  const Verification v = verifier.verify("ARM_COMMAND", old, kT0 + 31'000'000);
  EXPECT_EQ(v.verdict, Verdict::kStale);
  EXPECT_EQ(v.reason,
            "stale: auth_counter from 'sg-grasp' is 31.0 s older than this host's clock (max age "
            "30.0 s): a command replayed from before, or clock skew between hosts");
  arm_cmd_t ahead = move(2);
  signer.sign("ARM_COMMAND", ahead);
  const Verification w = verifier.verify("ARM_COMMAND", ahead, kT0 - 31'000'000);
  EXPECT_EQ(w.verdict, Verdict::kStale);
  EXPECT_NE(w.reason.find("ahead of this host's clock"), std::string::npos) << w.reason;
  EXPECT_EQ(verifier.senders(), 0u);  // neither was remembered
  EXPECT_TRUE(verifier.verify("ARM_COMMAND", ahead, kT0 - 29'000'000).accepted());
  // Extreme counters cannot overflow the check.
  CommandVerifier fresh(key);
  arm_cmd_t low = move(3);
  signer.sign("ARM_COMMAND", low);
  EXPECT_EQ(fresh.verify("ARM_COMMAND", low, std::numeric_limits<int64_t>::max()).verdict,
            Verdict::kStale);
  EXPECT_EQ(fresh.verify("ARM_COMMAND", low, std::numeric_limits<int64_t>::min()).verdict,
            Verdict::kStale);
  EXPECT_EQ(fresh.count(Verdict::kStale), 2);
}

// 100,000 random sender names, forged and then genuinely signed: the table never holds more than
// 64, the newest senders stay and the longest without an accepted command is forgotten first.
TEST_F(CommandAuth, SenderTableStaysBounded) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 100'000; ++i) {
    arm_cmd_t c = move(1);
    c.sender = std::to_string(rng());
    c.auth_counter = kT0;
    c.auth_tag[0] = 1;
    verifier.verify("ARM_COMMAND", c, kT0);
  }
  EXPECT_EQ(verifier.senders(), 0u);
  CommandSigner main_sender(key, "sg-grasp", clock);
  arm_cmd_t last_main{};
  for (int i = 0; i < 100'000; ++i) {
    CommandSigner someone(key, "s" + std::to_string(rng()), clock);
    arm_cmd_t c = move(1);
    someone.sign("ARM_COMMAND", c);
    ASSERT_TRUE(verifier.verify("ARM_COMMAND", c, kT0).accepted());
    ASSERT_LE(verifier.senders(), 64u);
    if (i % 32 == 0) {  // one sender that keeps talking is never forgotten
      last_main = move(2);
      main_sender.sign("ARM_COMMAND", last_main);
      ASSERT_TRUE(verifier.verify("ARM_COMMAND", last_main, kT0).accepted());
    }
  }
  EXPECT_EQ(verifier.senders(), 64u);
  // Its last command replayed is still known as a replay: it was never forgotten.
  EXPECT_EQ(verifier.verify("ARM_COMMAND", last_main, kT0).verdict, Verdict::kReplayed);
}

// The verdicts' names, as reports print them.
TEST(Verdicts, Names) {
  EXPECT_STREQ(to_string(Verdict::kAccepted), "accepted");
  EXPECT_STREQ(to_string(Verdict::kUnsigned), "unsigned");
  EXPECT_STREQ(to_string(Verdict::kBadTag), "bad tag");
  EXPECT_STREQ(to_string(Verdict::kReplayed), "replayed");
  EXPECT_STREQ(to_string(Verdict::kStale), "stale");
}

}  // namespace
}  // namespace sg::auth
