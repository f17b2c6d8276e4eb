// The bus-check pattern: deterministic, covers every type, and detects any changed byte. The
// hostile packets: typical messages, their windows, random bodies, truncations, foreign types.

#include "common/bus_check.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <stdexcept>

#include "common/message_fields.hpp"
#include "common/message_types.hpp"
#include "common/safe_decode.hpp"

namespace sg::bus_check {
namespace {

// Every type has its own channel, and the same utime always gives the same bytes.
TEST(BusCheck, ChannelsPerTypeAndDeterministicContents) {
  ASSERT_EQ(type_count(), static_cast<int>(std::tuple_size_v<MessageTypes>));
  std::set<std::string> channels;
  for (int i = 0; i < type_count(); ++i) {
    channels.insert(channel(i));
    EXPECT_EQ(encode(i, 123456789), encode(i, 123456789)) << type_name(i);
    EXPECT_NE(encode(i, 123456789), encode(i, 123456790)) << type_name(i);
  }
  EXPECT_EQ(static_cast<int>(channels.size()), type_count());
  EXPECT_EQ(channel(0), "BUS_CHECK_IMAGE_T");
}

// Intact messages verify; a flipped byte anywhere, or a truncation, does not.
TEST(BusCheck, VerifyDetectsEveryCorruption) {
  for (int i = 0; i < type_count(); ++i) {
    std::vector<uint8_t> bytes = encode(i, 1700000000000000 + i);
    auto verdict = verify(channel(i), bytes.data(), static_cast<int>(bytes.size()));
    ASSERT_TRUE(verdict.has_value());
    EXPECT_TRUE(verdict->intact) << type_name(i);
    EXPECT_EQ(verdict->utime, 1700000000000000 + i);
    for (size_t at = 0; at < bytes.size(); at += 1 + bytes.size() / 40) {
      bytes[at] ^= 0x10;
      verdict = verify(channel(i), bytes.data(), static_cast<int>(bytes.size()));
      EXPECT_FALSE(verdict->intact) << type_name(i) << " byte " << at;
      bytes[at] ^= 0x10;
    }
    verdict = verify(channel(i), bytes.data(), static_cast<int>(bytes.size()) - 1);
    EXPECT_FALSE(verdict->intact);
  }
}

// Messages on other channels are not judged.
TEST(BusCheck, OtherChannelsAreNotChecked) {
  const std::vector<uint8_t> bytes = encode(0, 1);
  EXPECT_FALSE(verify("CAMERA_LEFT", bytes.data(), static_cast<int>(bytes.size())).has_value());
}

}  // namespace
}  // namespace sg::bus_check

namespace sg::bus_check {
namespace {

/// Counts the empty strings and empty variable arrays of a message (a visitor for visit_fields).
struct EmptyFields {
  template <class T>
  void add(const std::string&, const T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      empty += value.empty();
    } else if constexpr (!std::is_arithmetic_v<T> && !std::is_array_v<T>) {
      empty += value.empty();
    }
  }
  int empty = 0;
};

/// Whether `bytes` decode as the type with index `type` (sg::safe_decode); `empty` counts the
/// empty strings and variable arrays of the message decoded.
bool decodes_as(int type, const std::vector<uint8_t>& bytes, int* empty = nullptr) {
  bool ok = false;
  int index = 0;
  for_each_message_type([&]<class T>() {
    if (index++ != type) return;
    T message{};
    ok = static_cast<bool>(safe_decode(bytes.data(), static_cast<int>(bytes.size()), message));
    EmptyFields fields;
    visit_fields(message, fields);
    if (empty != nullptr) *empty = fields.empty;
  });
  return ok;
}

std::vector<HostilePacket> of_kind(const std::vector<HostilePacket>& all, HostileKind kind) {
  std::vector<HostilePacket> some;
  for (const HostilePacket& p : all)
    if (p.kind == kind) some.push_back(p);
  return some;
}

// Every type's typical message decodes, with no empty string or variable array.
TEST(Hostile, TypicalMessagesAreWellFormedAndFull) {
  for (int i = 0; i < type_count(); ++i) {
    int empty = -1;
    EXPECT_TRUE(decodes_as(i, typical(i), &empty)) << type_name(i);
    EXPECT_EQ(empty, 0) << type_name(i);
    EXPECT_EQ(typical(i), typical(i)) << type_name(i);
  }
  EXPECT_EQ(type_index("point3_t"), 2);
  EXPECT_EQ(type_index("no_such_t"), -1);
}

// A type gives 4 (n - 11) windows, K random bodies, n truncations and one message of each other
// type, n being its typical message's size.
TEST(Hostile, PacketCountsPerKind) {
  HostileSettings settings;
  settings.random_bodies = 25;
  for (int i = 0; i < type_count(); ++i) {
    const auto n = static_cast<size_t>(typical(i).size());
    const std::vector<HostilePacket> all = hostile_packets(i, settings);
    EXPECT_EQ(of_kind(all, HostileKind::kWindow).size(), 4 * (n - 11)) << type_name(i);
    EXPECT_EQ(of_kind(all, HostileKind::kRandom).size(), 25u) << type_name(i);
    EXPECT_EQ(of_kind(all, HostileKind::kTruncated).size(), n) << type_name(i);
    EXPECT_EQ(of_kind(all, HostileKind::kForeign).size(), static_cast<size_t>(type_count() - 1));
  }
  settings.windows = settings.truncations = settings.foreign = false;
  EXPECT_EQ(hostile_packets(0, settings).size(), 25u);
}

// Window k of offset `at` is the typical message with bytes at..at+3 set to the k-th value,
// big-endian; every offset after the fingerprint gets all four values.
TEST(Hostile, WindowsOverwriteFourBytesBigEndian) {
  const int point = type_index("point3_t");
  const std::vector<uint8_t> base = typical(point);
  const auto windows = of_kind(hostile_packets(point, {}), HostileKind::kWindow);
  size_t k = 0;
  for (size_t at = 8; at + 4 <= base.size(); ++at) {
    for (const uint32_t value : kWindowValues) {
      const HostilePacket& p = windows.at(k++);
      ASSERT_EQ(p.bytes.size(), base.size());
      for (size_t b = 0; b < base.size(); ++b) {
        const uint8_t want =
            b >= at && b < at + 4 ? static_cast<uint8_t>(value >> (24 - 8 * (b - at))) : base[b];
        ASSERT_EQ(p.bytes[b], want) << p.what << " byte " << b;
      }
    }
  }
  EXPECT_EQ(windows[2].what, "point3_t bytes 8-11 = 0x7fffffff");
  EXPECT_EQ((std::vector<uint8_t>(windows[3].bytes.begin() + 8, windows[3].bytes.begin() + 12)),
            (std::vector<uint8_t>{0x3b, 0x9a, 0xca, 0x00}));  // 10^9
}

// A window over a length field claims an impossible length, and safe_decode refuses it: the
// trajectory's num_points (after utime, source_utime, start_utime, period_us) set to 0x7fffffff.
TEST(Hostile, WindowOverALengthFieldIsRefused) {
  const int traj = type_index("trajectory_t");
  const auto windows = of_kind(hostile_packets(traj, {}), HostileKind::kWindow);
  const size_t num_points_at = 8 + 4 * 8;
  const HostilePacket& p = windows.at((num_points_at - 8) * 4 + 2);
  EXPECT_EQ(p.what, "trajectory_t bytes 40-43 = 0x7fffffff");
  EXPECT_FALSE(decodes_as(traj, p.bytes));
  EXPECT_FALSE(decodes_as(traj, windows.at((num_points_at - 8) * 4 + 1).bytes));  // -1
  EXPECT_TRUE(decodes_as(traj, typical(traj)));
}

// Random bodies: the type's fingerprint, then 0 .. 2n random bytes; the same seed gives the same
// bodies, another seed others.
TEST(Hostile, RandomBodiesBehindTheFingerprintFromTheSeed) {
  const int arm = type_index("arm_cmd_t");
  const std::vector<uint8_t> base = typical(arm);
  HostileSettings settings;
  settings.windows = settings.truncations = settings.foreign = false;
  settings.random_bodies = 200;
  settings.seed = 7;
  const std::vector<HostilePacket> bodies = hostile_packets(arm, settings);
  std::set<size_t> lengths;
  for (const HostilePacket& p : bodies) {
    ASSERT_GE(p.bytes.size(), 8u);
    ASSERT_LE(p.bytes.size(), 8 + 2 * base.size());
    EXPECT_TRUE(std::equal(base.begin(), base.begin() + 8, p.bytes.begin())) << p.what;
    lengths.insert(p.bytes.size());
  }
  EXPECT_GT(lengths.size(), 100u);  // lengths spread over 0 .. 2n
  EXPECT_EQ(hostile_packets(arm, settings)[57].bytes, bodies[57].bytes);
  settings.seed = 8;
  EXPECT_NE(hostile_packets(arm, settings)[57].bytes, bodies[57].bytes);
}

// Truncations are every proper prefix, foreign messages every other type's typical message, and
// none of them decodes as the type.
TEST(Hostile, TruncationsAndForeignTypesNeverDecode) {
  for (int i = 0; i < type_count(); ++i) {
    const std::vector<uint8_t> base = typical(i);
    const auto all = hostile_packets(i, {});
    const auto cut = of_kind(all, HostileKind::kTruncated);
    for (size_t length = 0; length < cut.size(); ++length) {
      EXPECT_EQ(cut[length].bytes, std::vector<uint8_t>(base.begin(), base.begin() + length));
      EXPECT_FALSE(decodes_as(i, cut[length].bytes)) << cut[length].what;
    }
    for (const HostilePacket& p : of_kind(all, HostileKind::kForeign)) {
      EXPECT_NE(p.bytes, base);
      EXPECT_FALSE(decodes_as(i, p.bytes)) << p.what;
    }
  }
}

// The plan covers DESIGN's twelve channels (or those asked for) and numbers the packets round
// robin; an unknown channel is refused by name.
TEST(Hostile, PlanRoundRobinOverTheChannels) {
  HostileSettings settings;
  settings.random_bodies = 3;
  const HostilePlan all = plan_attack({}, settings);
  ASSERT_EQ(all.channels.size(), 12u);
  const HostilePlan two = plan_attack({"ARM_COMMAND", "OBJECT_POSITION"}, settings);
  ASSERT_EQ(two.channels.size(), 2u);
  EXPECT_EQ(two.channels[0].target.channel, "OBJECT_POSITION");  // in system_channels() order
  std::string channel;
  EXPECT_EQ(two.at(0, &channel)->bytes, two.channels[0].packets[0].bytes);
  EXPECT_EQ(channel, "OBJECT_POSITION");
  EXPECT_EQ(two.at(1, &channel)->bytes, two.channels[1].packets[0].bytes);
  EXPECT_EQ(channel, "ARM_COMMAND");
  EXPECT_EQ(two.at(2, &channel)->bytes, two.channels[0].packets[1].bytes);
  EXPECT_NE(two.at(two.total() - 1), nullptr);
  EXPECT_EQ(two.at(two.total()), nullptr);
  EXPECT_EQ(two.total(),
            static_cast<int64_t>(two.channels[0].packets.size() + two.channels[1].packets.size()));
  EXPECT_THROW(plan_attack({"ARM_COMAND"}, settings), std::invalid_argument);
}

// run_attack sends packets first..last in plan order, counting per channel.
TEST(Hostile, RunAttackSendsTheNumberedRange) {
  HostileSettings settings;
  settings.random_bodies = 2;
  HostilePlan plan = plan_attack({"GRASP_COMMAND", "SIM_ARM_STATE"}, settings);
  std::vector<std::vector<uint8_t>> sent;
  auto publish = [&](const std::string&, const HostilePacket& p) {
    sent.push_back(p.bytes);
    return true;
  };
  const int64_t n = run_attack(
      plan, 5, 104, 1e6, publish, [](int64_t, int64_t) {}, [] { return false; });
  ASSERT_EQ(n, 100);
  ASSERT_EQ(sent.size(), 100u);
  for (int64_t k = 0; k < 100; ++k) EXPECT_EQ(sent[k], plan.at(5 + k)->bytes) << k;
  EXPECT_EQ(plan.channels[0].sent + plan.channels[1].sent, 100);
  sent.clear();
  EXPECT_EQ(run_attack(
                plan, 0, 1 << 30, 1e6, publish, [](int64_t, int64_t) {},
                [&] { return sent.size() >= 10; }),
            10);
}

}  // namespace
}  // namespace sg::bus_check
