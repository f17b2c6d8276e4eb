// The bus-check pattern: deterministic, covers every type, and detects any changed byte.

#include "common/bus_check.hpp"

#include <gtest/gtest.h>

#include "common/message_types.hpp"

#include <set>

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
