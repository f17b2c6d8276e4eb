// Encode/decode round trips of every stereograsp message type with boundary values.

#include <gtest/gtest.h>

#include "tests/support/field_dump.hpp"
#include "tests/support/sample_messages.hpp"

namespace sg::test {
namespace {

template <class T>
class RoundTripTest : public ::testing::Test {};

using AllTypes = ::testing::Types<stereograsp::image_t, stereograsp::blob_t, stereograsp::point3_t,
                                  stereograsp::trajectory_t, stereograsp::arm_cmd_t,
                                  stereograsp::arm_status_t, stereograsp::grasp_command_t,
                                  stereograsp::grasp_status_t, stereograsp::sim_arm_state_t>;
TYPED_TEST_SUITE(RoundTripTest, AllTypes);

template <class T>
std::vector<uint8_t> encode(const T& message) {
  std::vector<uint8_t> bytes = encode_message(message);
  EXPECT_EQ(static_cast<int>(bytes.size()), message.getEncodedSize());
  return bytes;
}

// Every field survives encode then decode bit for bit, for empty, typical and extreme values.
TYPED_TEST(RoundTripTest, EveryFieldSurvivesForEveryKindOfValue) {
  for (SampleKind kind : {SampleKind::kEmpty, SampleKind::kTypical, SampleKind::kExtreme}) {
    const TypeParam original = make_sample<TypeParam>(kind);
    const std::vector<uint8_t> bytes = encode(original);
    TypeParam decoded{};
    ASSERT_EQ(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())),
              static_cast<int>(bytes.size()));
    EXPECT_EQ(dump(decoded), dump(original)) << "kind " << static_cast<int>(kind);
  }
}

// The samples really differ by kind, so the round trip above is not comparing zeros with zeros.
TYPED_TEST(RoundTripTest, SampleKindsDiffer) {
  const std::string empty = dump(make_sample<TypeParam>(SampleKind::kEmpty));
  const std::string typical = dump(make_sample<TypeParam>(SampleKind::kTypical));
  const std::string extreme = dump(make_sample<TypeParam>(SampleKind::kExtreme));
  EXPECT_NE(empty, typical);
  EXPECT_NE(typical, extreme);
  EXPECT_NE(extreme.find("utime=9223372036854775807"), std::string::npos) << extreme;
}

// Across all types the extreme samples hold NaN, both infinities, -0.0, the largest and the
// smallest doubles, and integer limits.
TEST(MessageTypes, ExtremeSamplesCoverEveryBoundary) {
  std::string all;
  for_each_message_type([&]<class T>() { all += dump(make_sample<T>(SampleKind::kExtreme)); });
  for (const char* marker : {"=d:7ff8000000000000", "=d:7ff0000000000000", "=d:fff0000000000000",
                             "=d:8000000000000000", "=d:7fefffffffffffff", "=d:0000000000000001",
                             "=-9223372036854775808", "=2147483647", "=-128"}) {
    EXPECT_NE(all.find(marker), std::string::npos) << marker;
  }
}

// A message cut short by one byte is refused, not read past its end.
TYPED_TEST(RoundTripTest, TruncatedBufferIsRefused) {
  const std::vector<uint8_t> bytes = encode(make_sample<TypeParam>(SampleKind::kTypical));
  TypeParam decoded{};
  EXPECT_LT(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size()) - 1), 0);
}

// Bytes of another type are refused by the fingerprint check.
TYPED_TEST(RoundTripTest, OtherTypesBytesAreRefused) {
  for_each_message_type([]<class Other>() {
    if constexpr (!std::is_same_v<Other, TypeParam>) {
      const std::vector<uint8_t> bytes = encode(make_sample<Other>(SampleKind::kTypical));
      TypeParam decoded{};
      EXPECT_LT(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0)
          << Other::getTypeName() << " decoded as " << TypeParam::getTypeName();
    }
  });
}

// Each type has its own fingerprint, and every type starts with utime (DESIGN §1).
TEST(MessageTypes, FingerprintsAreDistinctAndUtimeComesFirst) {
  std::set<int64_t> hashes;
  int count = 0;
  for_each_message_type([&]<class T>() {
    ++count;
    hashes.insert(T::getHash());
    T message{};
    message.utime = 0x0102030405060708;
    make_consistent(message);
    std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
    message.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    // After the 8-byte fingerprint, the first field is the big-endian utime.
    EXPECT_EQ(bytes[8], 0x01) << T::getTypeName();
    EXPECT_EQ(bytes[15], 0x08) << T::getTypeName();
  });
  EXPECT_EQ(count, 10);  // the .lcm files in lcmtypes/
  EXPECT_EQ(static_cast<int>(hashes.size()), count);
}

}  // namespace
}  // namespace sg::test
