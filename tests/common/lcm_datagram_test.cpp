// LCM's UDP wire format read without LCM: datagrams from LCM's own publisher reassembled byte for
// byte, and every datagram that breaks the format or loses a fragment refused in one line.

#include "common/lcm_datagram.hpp"

#include <gtest/gtest.h>
#include <poll.h>

#include <lcm/lcm-cpp.hpp>
#include <random>

#include "common/udpm_socket.hpp"
#include "tests/integration/multicast_guard.hpp"

namespace sg {
namespace {

void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<uint8_t>(v >> s));
}
void put16(std::vector<uint8_t>& b, uint16_t v) {
  b.push_back(static_cast<uint8_t>(v >> 8));
  b.push_back(static_cast<uint8_t>(v));
}

std::vector<uint8_t> short_datagram(uint32_t seqno, const std::string& channel,
                                    const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> b;
  put32(b, kLcmMagicShort);
  put32(b, seqno);
  b.insert(b.end(), channel.begin(), channel.end());
  b.push_back(0);
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

/// Fragment `no` of `count` of a message of `size` bytes; `part` is its bytes at `offset`.
std::vector<uint8_t> fragment(uint32_t seqno, uint32_t size, uint32_t offset, uint16_t no,
                              uint16_t count, const std::string& channel,
                              const std::vector<uint8_t>& part) {
  std::vector<uint8_t> b;
  put32(b, kLcmMagicLong);
  put32(b, seqno);
  put32(b, size);
  put32(b, offset);
  put16(b, no);
  put16(b, count);
  if (no == 0) b.insert(b.end(), channel.begin(), channel.end()), b.push_back(0);
  b.insert(b.end(), part.begin(), part.end());
  return b;
}

std::vector<uint8_t> bytes(size_t n, uint32_t seed) {
  std::mt19937 random(seed);
  std::vector<uint8_t> b(n);
  for (uint8_t& x : b) x = static_cast<uint8_t>(random());
  return b;
}

std::vector<uint8_t> part(const std::vector<uint8_t>& m, size_t from, size_t n) {
  return {m.begin() + static_cast<long>(from), m.begin() + static_cast<long>(from + n)};
}

/// Feeds datagrams to an assembler that wants CAMERA_LEFT only; keeps what comes out.
struct Feeder {
  LcmDatagramAssembler assembler;
  std::vector<std::pair<std::string, std::vector<uint8_t>>> messages;
  std::vector<std::string> refusals;

  explicit Feeder(LcmDatagramAssembler::Limits limits = {}) : assembler(limits) {}
  void add(const std::vector<uint8_t>& d, uint64_t sender = 1) {
    const auto m = assembler.add(
        sender, d.data(), d.size(), [](std::string_view c) { return c == "CAMERA_LEFT"; },
        [&](const std::string& why) { refusals.push_back(why); });
    if (m)
      messages.emplace_back(std::string(m->channel),
                            std::vector<uint8_t>(m->data, m->data + m->size));
  }
};

// Every message LCM's own publisher sends, short or in fragments, comes out whole and exact.
TEST(LcmDatagram, ReassemblesWhatLcmPublishes) {
  ASSERT_TRUE(test::multicast_available(7975));
  const std::string url = test::test_url(7975) + "&recv_buf_size=4194304";
  const std::optional<UdpmEndpoint> endpoint = udpm_endpoint(url);
  ASSERT_TRUE(endpoint);
  UdpmSocket socket(*endpoint);
  lcm::LCM publisher(url);
  ASSERT_TRUE(publisher.good());
  LcmDatagramAssembler assembler;
  // Around LCM's largest short message (65,499 bytes with the channel and its NUL) and a raw
  // 640x480 frame.
  for (const size_t size : {size_t{0}, size_t{1}, size_t{40000}, size_t{65487}, size_t{65488},
                            size_t{65500}, size_t{200000}, size_t{921654}}) {
    const std::vector<uint8_t> sent = bytes(size, static_cast<uint32_t>(size));
    ASSERT_EQ(publisher.publish("CAMERA_LEFT", sent.data(), static_cast<unsigned>(size)), 0);
    std::optional<std::vector<uint8_t>> received;
    int datagrams = 0;
    std::vector<std::string> refusals;
    UdpmSocket::Datagram d;
    while (!received && poll(std::vector<pollfd>{{socket.fd(), POLLIN, 0}}.data(), 1, 2000) > 0) {
      while (!received && socket.receive(d)) {
        ++datagrams;
        const auto m = assembler.add(
            d.sender, d.bytes, d.size, [](std::string_view c) { return c == "CAMERA_LEFT"; },
            [&](const std::string& why) { refusals.push_back(why); });
        if (m) {
          EXPECT_EQ(m->channel, "CAMERA_LEFT");
          received.emplace(m->data, m->data + m->size);
        }
      }
    }
    ASSERT_TRUE(received) << size << " bytes: nothing came out of " << datagrams << " datagrams";
    EXPECT_TRUE(*received == sent) << size << " bytes";
    EXPECT_TRUE(refusals.empty()) << refusals.front();
    EXPECT_EQ(datagrams > 1, size > 65487) << size << " bytes in " << datagrams << " datagrams";
    EXPECT_EQ(assembler.in_assembly(), 0u);
  }
}

// A message in four fragments is whole after the fourth, not before.
TEST(LcmDatagram, FragmentsInOrderMakeTheMessage) {
  Feeder f;
  const std::vector<uint8_t> m = bytes(1000, 7);
  f.add(fragment(5, 1000, 0, 0, 4, "CAMERA_LEFT", part(m, 0, 100)));
  f.add(fragment(5, 1000, 100, 1, 4, "", part(m, 100, 300)));
  f.add(fragment(5, 1000, 400, 2, 4, "", part(m, 400, 300)));
  EXPECT_TRUE(f.messages.empty());
  f.add(fragment(5, 1000, 700, 3, 4, "", part(m, 700, 300)));
  ASSERT_EQ(f.messages.size(), 1u);
  EXPECT_EQ(f.messages[0].first, "CAMERA_LEFT");
  EXPECT_TRUE(f.messages[0].second == m);
  EXPECT_TRUE(f.refusals.empty());
}

// Each kind of broken datagram is refused with its own reason, and nothing comes out.
TEST(LcmDatagram, BrokenDatagramsAreRefusedInOneLine) {
  const std::vector<std::pair<std::vector<uint8_t>, std::string>> cases = {
      {{0x4c, 0x43}, "shorter than LCM's magic number"},
      {{'H', 'T', 'T', 'P', '/', '1'}, "not an LCM datagram (magic 0x48545450)"},
      {{0x4c, 0x43, 0x30, 0x32, 0, 0, 0}, "shorter than its header"},
      {short_datagram(1, "", {1, 2}), "an empty channel name"},
      {short_datagram(1, std::string(64, 'C'), {1}), "longer than LCM's 63 bytes"},
      {part(short_datagram(1, "CAMERA_LEFT", {}), 0, 15), "a channel name without its NUL"},
      {fragment(1, 100, 0, 2, 2, "CAMERA_LEFT", {}), "an LC03 fragment 2 of 2"},
      {fragment(1, 100, 0, 0, 0, "CAMERA_LEFT", {}), "an LC03 fragment 0 of 0"},
      {fragment(1, 100, 90, 1, 2, "", bytes(20, 1)), "bytes 90..110 of a 100-byte message"},
      {part(fragment(1, 100, 0, 1, 2, "", {}), 0, 19), "shorter than its header"},
  };
  for (const auto& [datagram, reason] : cases) {
    Feeder f;
    f.add(datagram);
    EXPECT_TRUE(f.messages.empty());
    ASSERT_EQ(f.refusals.size(), 1u) << reason;
    EXPECT_NE(f.refusals[0].find(reason), std::string::npos) << f.refusals[0];
  }
}

// A message that loses, repeats or reorders a fragment is dropped and reported; the next is whole.
TEST(LcmDatagram, AMessageMissingAFragmentIsDroppedAndReported) {
  const std::vector<uint8_t> m = bytes(300, 3);
  auto f0 = [&](uint32_t seq) {
    return fragment(seq, 300, 0, 0, 3, "CAMERA_LEFT", part(m, 0, 100));
  };
  auto f1 = [&](uint32_t seq) { return fragment(seq, 300, 100, 1, 3, "", part(m, 100, 100)); };
  auto f2 = [&](uint32_t seq) { return fragment(seq, 300, 200, 2, 3, "", part(m, 200, 100)); };
  const std::vector<std::pair<std::vector<std::vector<uint8_t>>, std::string>> cases = {
      {{f0(1), f2(1)}, "fragment 2 came where 1 was due"},
      {{f0(1), f1(1), f1(1)}, "fragment 1 came where 2 was due"},
      {{f0(1), f0(1)}, "its first fragment came again"},
      {{f0(1), f1(1), f0(2)}, "the sender's next message came before its last fragment"},
      {{f0(1), short_datagram(2, "PROCESS_STATUS", {1})}, "next message came before"},
      {{f0(1), fragment(1, 300, 150, 1, 3, "", part(m, 150, 100))}, "starts at byte 150, not 100"},
      {{f0(1), fragment(1, 400, 100, 1, 3, "", part(m, 100, 100))}, "another message's size"},
      {{f0(1), f1(1), fragment(1, 300, 200, 2, 3, "", part(m, 200, 50))}, "hold 250 bytes"},
  };
  for (const auto& [datagrams, reason] : cases) {
    Feeder f;
    for (const auto& d : datagrams) f.add(d);
    EXPECT_TRUE(f.messages.empty()) << reason;
    ASSERT_EQ(f.refusals.size(), 1u) << reason;
    EXPECT_NE(f.refusals[0].find(reason), std::string::npos) << f.refusals[0];
    EXPECT_EQ(f.refusals[0].rfind("CAMERA_LEFT: message 1 (300 bytes", 0), 0u) << f.refusals[0];
    for (const auto& d : {f0(9), f1(9), f2(9)}) f.add(d);
    ASSERT_EQ(f.messages.size(), 1u) << "after: " << reason;
    EXPECT_TRUE(f.messages[0].second == m);
  }
}

// Channels nobody wants pass without a word, their fragments too, and are never assembled.
TEST(LcmDatagram, OtherChannelsAreSkippedQuietly) {
  Feeder f;
  f.add(short_datagram(1, "OBJECT_POSITION", bytes(50, 1)));
  f.add(fragment(2, 300, 0, 0, 3, "CAMERA_RIGHT", bytes(100, 2)));
  EXPECT_EQ(f.assembler.in_assembly(), 0u);
  f.add(fragment(2, 300, 100, 1, 3, "", bytes(100, 3)));
  f.add(fragment(2, 300, 200, 2, 3, "", bytes(100, 4)));
  EXPECT_TRUE(f.messages.empty());
  EXPECT_TRUE(f.refusals.empty()) << f.refusals.front();
}

// A message claiming more than the bound is refused before anything is allocated for it.
TEST(LcmDatagram, AMessageAboveTheBoundIsRefused) {
  Feeder f(LcmDatagramAssembler::Limits{1000, 8, 100000});
  f.add(fragment(1, 1001, 0, 0, 2, "CAMERA_LEFT", bytes(10, 1)));
  EXPECT_EQ(f.assembler.in_assembly(), 0u);
  ASSERT_EQ(f.refusals.size(), 1u);
  EXPECT_EQ(f.refusals[0], "CAMERA_LEFT: a 1001-byte message, above the bound of 1000");
  f.add(short_datagram(2, "CAMERA_LEFT", bytes(1001, 2)));  // one datagram: the same bound
  ASSERT_EQ(f.refusals.size(), 2u);
  EXPECT_EQ(f.refusals[1], "CAMERA_LEFT: a 1001-byte message, above the bound of 1000");
  EXPECT_TRUE(f.messages.empty());
  Feeder g;  // the default bound is 64 MiB and a header: 2^32 - 1 claimed is refused
  g.add(fragment(1, 0xffffffffu, 0, 0, 2, "CAMERA_LEFT", bytes(10, 1)));
  EXPECT_EQ(g.refusals.size(), 1u);
}

// More senders than the bound: the least recently fed message is dropped, the others complete.
TEST(LcmDatagram, SendersInAssemblyAreBounded) {
  Feeder f(LcmDatagramAssembler::Limits{1000, 2, 100000});
  const std::vector<uint8_t> m = bytes(200, 5);
  for (uint64_t sender = 1; sender <= 3; ++sender)
    f.add(fragment(7, 200, 0, 0, 2, "CAMERA_LEFT", part(m, 0, 100)), sender);
  EXPECT_EQ(f.assembler.in_assembly(), 2u);
  ASSERT_EQ(f.refusals.size(), 1u);
  EXPECT_NE(f.refusals[0].find("more than 2 senders"), std::string::npos) << f.refusals[0];
  for (uint64_t sender = 1; sender <= 3; ++sender)
    f.add(fragment(7, 200, 100, 1, 2, "", part(m, 100, 100)), sender);
  EXPECT_EQ(f.messages.size(), 2u) << "senders 2 and 3; sender 1's start was dropped";
  EXPECT_EQ(f.assembler.in_assembly(), 0u);
}

// Buffers held are bounded: a third sender's message that would pass the bound drops the least
// recently fed one, and a finished message's buffer is freed before any assembly is dropped.
TEST(LcmDatagram, BuffersHeldAreBounded) {
  Feeder f(LcmDatagramAssembler::Limits{1000, 4, 2500});
  const std::vector<uint8_t> m = bytes(1000, 6);
  for (uint64_t sender = 1; sender <= 2; ++sender)
    f.add(fragment(3, 1000, 0, 0, 2, "CAMERA_LEFT", part(m, 0, 500)), sender);
  EXPECT_EQ(f.assembler.held(), 2000u);
  f.add(fragment(3, 1000, 500, 1, 2, "", part(m, 500, 500)), 2);  // sender 2's is whole
  ASSERT_EQ(f.messages.size(), 1u);
  f.add(fragment(4, 1000, 0, 0, 2, "CAMERA_LEFT", part(m, 0, 500)), 3);  // reuses its buffer
  EXPECT_TRUE(f.refusals.empty());
  EXPECT_EQ(f.assembler.held(), 2000u);
  f.add(fragment(5, 1000, 0, 0, 2, "CAMERA_LEFT", part(m, 0, 500)), 4);
  ASSERT_EQ(f.refusals.size(), 1u);
  EXPECT_NE(f.refusals[0].find("message 3 (1000 bytes, 1 of 2 fragments) dropped: the buffers "
                               "held would pass 2500 bytes"),
            std::string::npos)
      << f.refusals[0];
  EXPECT_LE(f.assembler.held(), 2500u);
  EXPECT_EQ(f.assembler.in_assembly(), 2u);
  f.add(fragment(5, 1000, 500, 1, 2, "", part(m, 500, 500)), 4);
  ASSERT_EQ(f.messages.size(), 2u);
  EXPECT_TRUE(f.messages[1].second == m);
}

// A channel name's bytes outside printable ASCII are written as \xNN: a report stays one line
// (found by the lcm_datagram fuzz target).
TEST(LcmDatagram, ReportsStayOneLine) {
  LcmDatagramAssembler assembler(LcmDatagramAssembler::Limits{100, 4, 1000});
  std::vector<std::string> refusals;
  const std::vector<uint8_t> d = fragment(1, 200, 0, 0, 2, "CAM\nERA\\", {1});
  assembler.add(
      1, d.data(), d.size(), [](std::string_view) { return true; },
      [&](const std::string& why) { refusals.push_back(why); });
  ASSERT_EQ(refusals.size(), 1u);
  EXPECT_EQ(refusals[0], "CAM\\x0aERA\\x5c: a 200-byte message, above the bound of 100");
}

// A short message on a wanted channel is its payload, pointing into the datagram.
TEST(LcmDatagram, AShortMessageIsItsPayload) {
  const std::vector<uint8_t> d = short_datagram(42, "CAMERA_LEFT", {9, 8, 7});
  std::string why;
  const auto parsed = parse_lcm_datagram(d.data(), d.size(), &why);
  ASSERT_TRUE(parsed) << why;
  EXPECT_FALSE(parsed->fragment);
  EXPECT_EQ(parsed->seqno, 42u);
  EXPECT_EQ(parsed->channel, "CAMERA_LEFT");
  EXPECT_EQ(parsed->data, d.data() + 8 + 12);
  EXPECT_EQ(parsed->size, 3u);
}

// The endpoint of an LCM URL: LCM's defaults, the URL's address, port and buffer, other providers.
TEST(UdpmEndpoint, ReadsLcmUrls) {
  const auto e = udpm_endpoint("udpm://239.255.76.99:7990?ttl=1&recv_buf_size=2097152");
  ASSERT_TRUE(e);
  EXPECT_EQ(e->group, "239.255.76.99");
  EXPECT_EQ(e->port, 7990);
  EXPECT_EQ(e->recv_buf_size, 2097152);
  const auto d = udpm_endpoint("udpm://");
  ASSERT_TRUE(d);
  EXPECT_EQ(d->group, "239.255.76.67");
  EXPECT_EQ(d->port, 7667);
  EXPECT_FALSE(udpm_endpoint("memq://"));
  EXPECT_FALSE(udpm_endpoint("tcpq"));  // no "://": a provider's name alone
  const auto bare = udpm_endpoint("udpm");
  ASSERT_TRUE(bare);
  EXPECT_EQ(bare->group, "239.255.76.67");
  EXPECT_FALSE(udpm_endpoint("file:///tmp/x.lcm?mode=r"));
  EXPECT_THROW(udpm_endpoint("udpm://239.255.76.67:99999"), std::invalid_argument);
  EXPECT_THROW(udpm_endpoint("udpm://not-an-address:7667"), std::invalid_argument);
  EXPECT_THROW(udpm_endpoint("udpm://239.255.76.67:7667?recv_buf_size=-1"), std::invalid_argument);
}

}  // namespace
}  // namespace sg
