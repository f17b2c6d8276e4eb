// The vouching trailer's layout (common/vouch_trailer.hpp): round trips, the byte layout counted by
// hand, every truncation and every single-byte change of the end refused or read as what it is,
// never read outside the bytes; and what a reader without a guard takes off.

#include "common/vouch_trailer.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace sg {
namespace {

VouchTrailer sample() {
  VouchTrailer t;
  t.sender = "sg-predictor";
  t.instance = 0x01020304;
  t.counter = 0x0a0b0c0d0e0f1011;
  VouchTag a{"sg-grasp", {}}, b{"sg-viewer", {}};
  for (size_t i = 0; i < kVouchTagSize; ++i) {
    a.tag[i] = static_cast<uint8_t>(i);
    b.tag[i] = static_cast<uint8_t>(0xf0 + i);
  }
  t.tags = {a, b};
  return t;
}

// A trailer appended to a payload reads back as it was written, and the payload's size with it.
TEST(VouchTrailer, RoundTrip) {
  std::vector<uint8_t> bytes = {1, 2, 3, 4, 5};
  append_vouch_trailer(bytes, sample());
  const TrailerParse p = parse_vouch_trailer(bytes.data(), bytes.size());
  ASSERT_EQ(p.kind, TrailerParse::kFound) << p.why;
  EXPECT_EQ(p.payload_size, 5u);
  EXPECT_EQ(p.trailer, sample());
  EXPECT_EQ(vouched_payload_size(bytes.data(), bytes.size()), 5u);
  EXPECT_EQ(bytes.size(), 5 + vouch_trailer_size("sg-predictor", sample().tags));
}

// The layout byte by byte, counted by hand: sender, instance, counter, no tags, length, magic.
TEST(VouchTrailer, LayoutCountedByHand) {
  VouchTrailer t;
  t.sender = "ab";
  t.instance = 0x11223344;
  t.counter = 0x0102030405060708;
  std::vector<uint8_t> bytes;
  append_vouch_trailer(bytes, t);
  const std::vector<uint8_t> expected = {2, 'a', 'b', 0x11, 0x22, 0x33, 0x44, 1,   2,   3,   4,
                                         5, 6,   7,   8,    0,    0,    22,   'S', 'G', 'v', '1'};
  EXPECT_EQ(bytes, expected);
}

// Bytes that do not end in the magic are an unvouched message, whole.
TEST(VouchTrailer, NoMagicIsNoTrailer) {
  const std::vector<uint8_t> bytes = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  const TrailerParse p = parse_vouch_trailer(bytes.data(), bytes.size());
  EXPECT_EQ(p.kind, TrailerParse::kNone);
  EXPECT_EQ(p.payload_size, bytes.size());
  EXPECT_EQ(parse_vouch_trailer(nullptr, 0).kind, TrailerParse::kNone);
}

// Every prefix of a vouched message that still ends in the magic is malformed or a shorter
// message; cutting the front off keeps the trailer; no parse reads outside its bytes (ASan).
TEST(VouchTrailer, EveryCutAndEveryByteChangeIsHandled) {
  std::vector<uint8_t> bytes = {9, 9, 9};
  append_vouch_trailer(bytes, sample());
  for (size_t n = 0; n < bytes.size(); ++n) {
    const std::vector<uint8_t> cut(bytes.begin() + static_cast<long>(n), bytes.end());
    const TrailerParse p = parse_vouch_trailer(cut.data(), cut.size());
    if (cut.size() < 4) {
      EXPECT_EQ(p.kind, TrailerParse::kNone) << n;  // not even the magic is left
    } else if (n <= 3) {
      ASSERT_EQ(p.kind, TrailerParse::kFound) << n;
      EXPECT_EQ(p.payload_size, 3 - n);
    } else {
      EXPECT_EQ(p.kind, TrailerParse::kMalformed) << n;
      EXPECT_FALSE(p.why.empty());
    }
  }
  int found = 0;
  for (size_t i = 3; i + 6 < bytes.size(); ++i) {
    for (const int v : {0, 0xff, 0x41}) {
      std::vector<uint8_t> changed = bytes;
      if (changed[i] == v) continue;
      changed[i] = static_cast<uint8_t>(v);
      const TrailerParse p = parse_vouch_trailer(changed.data(), changed.size());
      if (p.kind == TrailerParse::kFound) {
        ++found;  // a changed counter, instance or tag byte still parses: the tag catches it
        EXPECT_NE(p.trailer, sample());
      }
    }
  }
  EXPECT_GT(found, 0);
}

// The length word may not claim more than the message or less than a trailer.
TEST(VouchTrailer, LengthWordIsBounded) {
  std::vector<uint8_t> bytes;
  append_vouch_trailer(bytes, sample());
  std::vector<uint8_t> big = bytes;
  big[big.size() - 6] = 0xff;
  EXPECT_EQ(parse_vouch_trailer(big.data(), big.size()).kind, TrailerParse::kMalformed);
  std::vector<uint8_t> small = bytes;
  small[small.size() - 6] = 0;
  small[small.size() - 5] = 3;
  EXPECT_EQ(parse_vouch_trailer(small.data(), small.size()).kind, TrailerParse::kMalformed);
  const std::vector<uint8_t> magic_only = {'S', 'G', 'v', '1'};
  EXPECT_EQ(parse_vouch_trailer(magic_only.data(), 4).kind, TrailerParse::kMalformed);
}

// Names are 1-32 printable name characters; the writer refuses others and more than 32 tags.
TEST(VouchTrailer, NamesAndTagCountAreChecked) {
  EXPECT_TRUE(valid_vouch_name("sg-arm-driver@lab1:42"));
  EXPECT_FALSE(valid_vouch_name(""));
  EXPECT_FALSE(valid_vouch_name(std::string(33, 'a')));
  EXPECT_FALSE(valid_vouch_name("a b"));
  EXPECT_FALSE(valid_vouch_name(std::string("a\0b", 3)));
  std::vector<uint8_t> bytes;
  VouchTrailer t = sample();
  t.sender = "bad name";
  EXPECT_THROW(append_vouch_trailer(bytes, t), std::invalid_argument);
  t = sample();
  t.tags.resize(33, t.tags.front());
  EXPECT_THROW(append_vouch_trailer(bytes, t), std::invalid_argument);
  t.tags.resize(32);
  bytes.clear();
  append_vouch_trailer(bytes, t);
  EXPECT_EQ(parse_vouch_trailer(bytes.data(), bytes.size()).trailer.tags.size(), 32u);
}

}  // namespace
}  // namespace sg
