// safe_decode: every well-formed message of every type passes and decodes to what was encoded;
// the lengths that crash LCM's own decoder, and every 4-byte window of every type set to hostile
// values, are refused before any allocation, and nothing that passes the check can make LCM's
// decoder throw or read a different length.

#include "common/safe_decode.hpp"

#include <gtest/gtest.h>

#include <random>

#include "common/message_types.hpp"

namespace sg {
namespace {

using stereograsp::arm_cmd_t;
using stereograsp::image_t;
using stereograsp::trajectory_t;

/// Fills every field of a message with random values (strings of random length), through the
/// same field list the check walks.
struct Filler {
  std::mt19937_64& rng;
  template <class T>
  void add(const char*, T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      value.assign(std::uniform_int_distribution<size_t>(0, 40)(rng), 'a');
      for (char& c : value) c = static_cast<char>('a' + rng() % 26);
    } else if constexpr (std::is_array_v<T>) {
      using E = std::remove_all_extents_t<T>;
      E* first = reinterpret_cast<E*>(&value);
      for (size_t i = 0; i < sizeof(T) / sizeof(E); ++i) first[i] = random<E>();
    } else if constexpr (std::is_arithmetic_v<T>) {
      value = random<T>();
    }
  }
  template <class E>
  E random() {
    if constexpr (std::is_floating_point_v<E>) return std::uniform_real_distribution<E>(-9, 9)(rng);
    return static_cast<E>(rng());
  }
};

/// Variable arrays get a random length, and their length fields agree with them.
template <class M>
void fill_arrays(M&, std::mt19937_64&) {}
void fill_arrays(trajectory_t& t, std::mt19937_64& rng) {
  t.num_points = static_cast<int32_t>(rng() % 20);
  t.position.assign(static_cast<size_t>(t.num_points), std::vector<double>{1.0, -2.0, 3.5});
  t.position_sigma.assign(static_cast<size_t>(t.num_points), std::vector<double>{0.1, 0.2, 0.3});
}
void fill_arrays(stereograsp::process_status_t& m, std::mt19937_64& rng) {
  m.num_channels = static_cast<int32_t>(rng() % 6);
  m.num_peers = static_cast<int32_t>(rng() % 6);
  const auto c = static_cast<size_t>(m.num_channels), p = static_cast<size_t>(m.num_peers);
  m.channel.assign(c, "OBJECT_POSITION");
  m.messages_in.assign(c, static_cast<int64_t>(rng()));
  m.messages_out.assign(c, static_cast<int64_t>(rng()));
  m.rate_in_hz.assign(c, 4.0);
  m.rate_out_hz.assign(c, -0.5);
  m.peer.assign(p, "sg-vision@lab1:" + std::to_string(rng() % 99999));
  m.peer_utime.assign(p, static_cast<int64_t>(rng()));
  m.peer_recv_utime.assign(p, static_cast<int64_t>(rng()));
  m.peer_offset_us.assign(p, static_cast<int64_t>(rng()));
  m.peer_offset_error_us.assign(p, -1);
  m.num_unvouched = static_cast<int32_t>(rng() % 6);
  const auto u = static_cast<size_t>(m.num_unvouched);
  m.unvouched_channel.assign(u, "OBJECT_TRAJECTORY");
  m.unvouched_sender.assign(u, "sg-intruder");
  m.unvouched_verdict.assign(u, "not allowed");
  m.unvouched_count.assign(u, static_cast<int64_t>(rng()));
}
void fill_arrays(image_t& m, std::mt19937_64& rng) {
  m.size = static_cast<int32_t>(rng() % 300);
  m.data.assign(static_cast<size_t>(m.size), static_cast<uint8_t>(rng()));
}

template <class M>
M random_message(std::mt19937_64& rng) {
  M m{};
  Filler filler{rng};
  visit_fields(m, filler);
  fill_arrays(m, rng);
  return m;
}

/// Writes a big-endian int32 at `at`.
void put_int32(std::vector<uint8_t>& b, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<uint8_t>(v >> (24 - 8 * i));
}

/// The byte offset of the int32 length of an arm_cmd_t's sender (then auth_counter, auth_tag[32]).
size_t sender_length_offset(const arm_cmd_t& c) {
  return encode_message(c).size() - 40 - 4 - (c.sender.size() + 1);
}

template <class M>
class SafeDecodeEveryType : public ::testing::Test {};
template <class Tuple>
struct AsGtestTypes;
template <class... T>
struct AsGtestTypes<std::tuple<T...>> {
  using type = ::testing::Types<T...>;
};
using AllTypes = AsGtestTypes<MessageTypes>::type;  // every type, process_status_t included
TYPED_TEST_SUITE(SafeDecodeEveryType, AllTypes);

// Every well-formed message passes the check and decodes to bytes that re-encode identically.
TYPED_TEST(SafeDecodeEveryType, WellFormedMessagesPassAndRoundTrip) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 200; ++i) {
    const auto sent = random_message<TypeParam>(rng);
    const std::vector<uint8_t> bytes = encode_message(sent);
    TypeParam got{};
    const DecodeResult r = safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), got);
    ASSERT_TRUE(r) << r.reason;
    EXPECT_EQ(encode_message(got), bytes);
  }
}

// Every 4-byte window set to 0, -1, 2^31-1 or 10^9, and random bodies behind the right
// fingerprint: safe_decode never throws, and whatever it accepts is exactly what LCM decodes.
TYPED_TEST(SafeDecodeEveryType, HostileWindowsNeverThrow) {
  std::mt19937_64 rng(11);
  const std::vector<uint8_t> good = encode_message(random_message<TypeParam>(rng));
  int accepted = 0;
  for (const uint32_t value : {0u, 0xffffffffu, 0x7fffffffu, 1000000000u}) {
    for (size_t at = 8; at + 4 <= good.size(); ++at) {
      std::vector<uint8_t> bytes = good;
      put_int32(bytes, at, value);
      TypeParam m{};
      DecodeResult r;
      ASSERT_NO_THROW(r = safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), m));
      accepted += r ? 1 : 0;
      if (r) {
        EXPECT_EQ(encode_message(m), bytes);
      }
    }
  }
  for (int i = 0; i < 2000; ++i) {
    std::vector<uint8_t> bytes(good.begin(), good.begin() + 8);
    bytes.resize(8 + rng() % (good.size() + 16));
    for (size_t k = 8; k < bytes.size(); ++k) bytes[k] = static_cast<uint8_t>(rng());
    TypeParam m{};
    ASSERT_NO_THROW(safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), m));
  }
  EXPECT_GT(accepted, 0) << "values inside plain numbers are fine";
}

// A string length of 0 makes LCM's own decoder throw; safe_decode refuses it and names the field.
TEST(SafeDecode, ZeroStringLengthIsRefusedWhereLcmThrows) {
  arm_cmd_t c{};
  c.sender = "sg-grasp";
  std::vector<uint8_t> bytes = encode_message(c);
  put_int32(bytes, sender_length_offset(c), 0);
  arm_cmd_t raw{};
  EXPECT_ANY_THROW(raw.decode(bytes.data(), 0, static_cast<int>(bytes.size())))
      << "the defect this guards against";
  arm_cmd_t safe{};
  const DecodeResult r = safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), safe);
  EXPECT_FALSE(r);
  EXPECT_NE(r.reason.find("'sender'"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("string length 0"), std::string::npos) << r.reason;
}

// A string whose last byte is not NUL, and one longer than the bytes left, are refused.
TEST(SafeDecode, UnterminatedAndOverlongStringsAreRefused) {
  arm_cmd_t c{};
  c.sender = "abc";
  std::vector<uint8_t> bytes = encode_message(c);
  bytes[bytes.size() - 41] = 'x';
  arm_cmd_t m{};
  EXPECT_NE(safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), m).reason.find("NUL"),
            std::string::npos);
  bytes[bytes.size() - 41] = 0;
  put_int32(bytes, sender_length_offset(c), 4 + 40 + 1);  // one more than there is
  EXPECT_NE(safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), m).reason.find("left"),
            std::string::npos);
}

// A trajectory that claims -1, 10^8 or 10^9 points in a 54-byte packet is refused, naming the
// field and the claim (LCM's decoder would throw for -1 and allocate gigabytes for the others).
TEST(SafeDecode, AbsurdArrayLengthsAreRefusedBeforeAllocation) {
  trajectory_t t{};
  const std::vector<uint8_t> empty = encode_message(t);
  ASSERT_EQ(empty.size(), 54u);
  const size_t num_points_at = 8 + 4 * 8;
  for (const int64_t claim : {int64_t{-1}, int64_t{100000000}, int64_t{1000000000}}) {
    std::vector<uint8_t> bytes = empty;
    put_int32(bytes, num_points_at, static_cast<uint32_t>(claim));
    trajectory_t m{};
    const DecodeResult r = safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), m);
    EXPECT_FALSE(r) << claim;
    EXPECT_NE(r.reason.find("'position'"), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find("claims " + std::to_string(claim)), std::string::npos) << r.reason;
    EXPECT_EQ(m.position.capacity(), 0u) << "nothing allocated";
  }
}

// A claim within the bound but beyond the bytes received is refused by the byte count.
TEST(SafeDecode, ArrayLongerThanThePacketIsRefused) {
  trajectory_t t{};
  t.num_points = 2;
  t.position.assign(2, std::vector<double>(3, 0.5));
  t.position_sigma.assign(2, std::vector<double>(3, 0.01));
  std::vector<uint8_t> bytes = encode_message(t);
  put_int32(bytes, 8 + 4 * 8, 3);
  trajectory_t m{};
  const DecodeResult r = safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), m);
  EXPECT_FALSE(r);
  EXPECT_NE(r.reason.find("needs 72 bytes"), std::string::npos) << r.reason;
}

// Another type's fingerprint, a short packet and trailing bytes are refused.
TEST(SafeDecode, FingerprintSizeAndTrailingBytes) {
  std::vector<uint8_t> bytes = encode_message(stereograsp::point3_t{});
  trajectory_t t{};
  EXPECT_NE(
      safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), t).reason.find("fingerprint"),
      std::string::npos);
  stereograsp::point3_t p{};
  EXPECT_FALSE(safe_decode(bytes.data(), 5, p));
  EXPECT_FALSE(safe_decode(nullptr, 0, p));
  bytes.push_back(0);
  EXPECT_NE(safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), p)
                .reason.find("1 bytes after the end"),
            std::string::npos);
}

}  // namespace
}  // namespace sg
