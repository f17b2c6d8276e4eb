// The kernel filter on LCM datagrams (issue 19): through a real socket with the program attached,
// the well-formed starts of other channels' messages are dropped (and counted by the kernel as
// the socket's drops); the wanted channels, later fragments and every malformed datagram (for
// the reader to refuse and count) arrive.

#include "common/lcm_channel_filter.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <linux/sock_diag.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <optional>
#include <random>
#include <string>
#include <vector>

#include "common/lcm_datagram.hpp"

namespace sg {
namespace {

void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<uint8_t>(v >> s));
}

std::vector<uint8_t> short_datagram(const std::string& channel, size_t payload = 8) {
  std::vector<uint8_t> b;
  put32(b, kLcmMagicShort);
  put32(b, 1);
  b.insert(b.end(), channel.begin(), channel.end());
  b.push_back(0);
  b.resize(b.size() + payload, 0xab);
  return b;
}

std::vector<uint8_t> fragment(uint16_t no, const std::string& channel) {
  std::vector<uint8_t> b;
  put32(b, kLcmMagicLong);
  put32(b, 2);
  put32(b, 100000);  // message size
  put32(b, no * 60000u);
  b.push_back(static_cast<uint8_t>(no >> 8));
  b.push_back(static_cast<uint8_t>(no));
  b.push_back(0);
  b.push_back(2);  // fragments in the message
  if (no == 0) b.insert(b.end(), channel.begin(), channel.end()), b.push_back(0);
  b.resize(b.size() + 16, 0xcd);
  return b;
}

/// A receiving socket on 127.0.0.1 with the filter for `channels`, and a socket sending to it.
class Filtered {
 public:
  explicit Filtered(const std::vector<std::string>& channels)
      : in_(socket(AF_INET, SOCK_DGRAM, 0)), out_(socket(AF_INET, SOCK_DGRAM, 0)) {
    address_.sin_family = AF_INET;
    address_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t size = sizeof address_;
    if (bind(in_, reinterpret_cast<sockaddr*>(&address_), size) != 0 ||
        getsockname(in_, reinterpret_cast<sockaddr*>(&address_), &size) != 0)
      throw std::runtime_error("cannot bind a loopback socket");
    attach_lcm_channel_filter(in_, channels);
  }
  ~Filtered() { close(in_), close(out_); }
  int fd() const { return in_; }

  /// True when `datagram` reaches the socket: it is sent, then a marker every filter here lets
  /// through ("MARK"); the datagram passed when it comes first (loopback keeps the order).
  bool passes(const std::vector<uint8_t>& datagram) {
    send(datagram);
    send(short_datagram("MARK", 0));
    std::vector<uint8_t> first = receive();
    if (first == datagram && datagram != short_datagram("MARK", 0)) {
      EXPECT_EQ(receive(), short_datagram("MARK", 0));
      return true;
    }
    EXPECT_EQ(first, short_datagram("MARK", 0));
    return false;
  }

  /// The drops the kernel counted on the receiving socket (SO_MEMINFO, SK_MEMINFO_DROPS).
  uint32_t drops() const {
    uint32_t info[SK_MEMINFO_VARS] = {};
    socklen_t size = sizeof info;
    if (getsockopt(in_, SOL_SOCKET, SO_MEMINFO, info, &size) != 0) return ~0u;
    return info[SK_MEMINFO_DROPS];
  }

 private:
  void send(const std::vector<uint8_t>& d) {
    ASSERT_EQ(sendto(out_, d.data(), d.size(), 0, reinterpret_cast<sockaddr*>(&address_),
                     sizeof address_),
              static_cast<ssize_t>(d.size()));
  }
  std::vector<uint8_t> receive() {
    pollfd p{in_, POLLIN, 0};
    if (poll(&p, 1, 5000) != 1) return {};
    std::vector<uint8_t> b(70000);
    const ssize_t n = recv(in_, b.data(), b.size(), 0);
    b.resize(n > 0 ? static_cast<size_t>(n) : 0);
    return b;
  }
  int in_, out_;
  sockaddr_in address_{};
};

// A wanted channel's short message and first fragment pass; another channel's, and names that
// only begin or end like a wanted one, are dropped, and counted as the socket's drops.
TEST(LcmChannelFilter, PassesExactlyTheWantedChannels) {
  Filtered f({"OBJECT_POSITION", "PROCESS_STATUS", "MARK"});
  EXPECT_TRUE(f.passes(short_datagram("OBJECT_POSITION")));
  EXPECT_TRUE(f.passes(short_datagram("PROCESS_STATUS", 0)));
  EXPECT_TRUE(f.passes(fragment(0, "OBJECT_POSITION")));
  const uint32_t before = f.drops();
  EXPECT_FALSE(f.passes(short_datagram("CAMERA_LEFT")));
  EXPECT_FALSE(f.passes(short_datagram("OBJECT_POSITION_2")));  // longer
  EXPECT_FALSE(f.passes(short_datagram("OBJECT_POSITIO")));     // shorter
  EXPECT_FALSE(f.passes(short_datagram("XBJECT_POSITION")));
  EXPECT_FALSE(f.passes(fragment(0, "CAMERA_LEFT")));
  EXPECT_FALSE(f.passes(short_datagram(std::string(63, 'X'), 0)));  // LCM's longest, at the end
  EXPECT_EQ(f.drops() - before, 6u);
}

// A later fragment carries no channel and always passes (the reader keeps it only with its
// first fragment); so does every datagram that is not a well-formed start of a message, for the
// reader to refuse with its reason: not LCM's, cut short, a name empty, without its NUL or
// longer than LCM's 63 bytes.
TEST(LcmChannelFilter, LaterFragmentsAndMalformedDatagramsPass) {
  Filtered f({"MARK", "CAMERA_LEFT"});
  EXPECT_TRUE(f.passes(fragment(1, "")));
  EXPECT_TRUE(f.passes(fragment(65535, "")));
  EXPECT_TRUE(f.passes({'G', 'E', 'T', ' ', '/', ' ', 'H', 'T', 'T', 'P'}));
  EXPECT_TRUE(f.passes({}));
  EXPECT_TRUE(f.passes({'L', 'C', '0'}));
  EXPECT_TRUE(f.passes({'L', 'C', '0', '2'}));
  EXPECT_TRUE(f.passes(short_datagram("", 4)));
  EXPECT_TRUE(f.passes(short_datagram(std::string(64, 'X'), 4)));
  std::vector<uint8_t> cut = short_datagram("OTHER", 0);
  cut.pop_back();  // no NUL after the name
  EXPECT_TRUE(f.passes(cut));
  std::vector<uint8_t> cut_fragment = fragment(0, "OTHER");
  cut_fragment.resize(20);  // ends in the fragment header
  EXPECT_TRUE(f.passes(cut_fragment));
  EXPECT_EQ(f.drops(), 0u);
}

// Names of every length LCM allows (1..63 bytes: each tail of words, halves and bytes) pass, and
// the same name with its last byte changed does not.
TEST(LcmChannelFilter, EveryNameLength) {
  for (size_t n = 1; n <= kLcmMaxChannel; ++n) {
    std::string name(n, 'a');
    for (size_t i = 0; i < n; ++i) name[i] = static_cast<char>('A' + (i * 7 + n) % 26);
    Filtered f({name, "MARK"});
    EXPECT_TRUE(f.passes(short_datagram(name))) << n;
    EXPECT_TRUE(f.passes(fragment(0, name))) << n;
    std::string other = name;
    other.back() = other.back() == 'Z' ? 'Y' : 'Z';
    EXPECT_FALSE(f.passes(short_datagram(other))) << n;
  }
}

// Against LcmDatagramAssembler, the parser that reads these datagrams in user space: of random
// datagrams (both magics, random channels and fragment numbers, random cuts), the filter passes
// each the assembler refuses before it reads a channel and each whose channel it reads as a
// wanted one, and drops each whose channel it reads as another's.
TEST(LcmChannelFilter, AgreesWithTheAssemblerOnRandomDatagrams) {
  const std::vector<std::string> names = {"CAMERA_LEFT", "CAMERA_RIGHT", "CAMERA_LEF", "C"};
  const auto wanted = [](std::string_view c) { return c == "CAMERA_LEFT" || c == "C"; };
  Filtered f({"CAMERA_LEFT", "C", "MARK"});
  std::mt19937 random(19);
  int taken = 0, others = 0;
  for (int i = 0; i < 400; ++i) {
    const std::string& channel = names[random() % names.size()];
    std::vector<uint8_t> d = random() % 2 ? short_datagram(channel, random() % 4)
                                          : fragment(static_cast<uint16_t>(random() % 3), channel);
    if (random() % 4 == 0) d.resize(random() % d.size());
    std::optional<std::string> read;  // the channel the assembler read, if it got that far
    bool refused = false;
    LcmDatagramAssembler assembler;
    assembler.add(
        1, d.data(), d.size(), [&](std::string_view c) { return read = std::string(c), wanted(c); },
        [&](const std::string&) { refused = true; });
    const bool passed = f.passes(d);
    if (!read) {  // refused before its channel (the reader must see it to count it), or a later
      EXPECT_TRUE(passed) << i << (refused ? " refused" : " fragment");  // fragment
    } else if (wanted(*read)) {
      ++taken;
      EXPECT_TRUE(passed) << i << ": " << *read;
    } else {
      ++others;
      EXPECT_FALSE(passed) << i << ": " << *read;
    }
  }
  EXPECT_GT(taken, 50);
  EXPECT_GT(others, 50);
}

// Only a plain name is a single channel to LCM's anchored regex; anything with a metacharacter,
// or too long, may match others.
TEST(LcmChannelFilter, PlainChannelNames) {
  EXPECT_TRUE(is_plain_channel_name("OBJECT_POSITION"));
  EXPECT_TRUE(is_plain_channel_name("lab-1/arm:cmd"));
  EXPECT_FALSE(is_plain_channel_name("BLOB_(LEFT|RIGHT)"));
  EXPECT_FALSE(is_plain_channel_name(".*"));
  EXPECT_FALSE(is_plain_channel_name("A.B"));
  EXPECT_FALSE(is_plain_channel_name("CAMERA_[LR]"));
  EXPECT_FALSE(is_plain_channel_name(""));
  EXPECT_FALSE(is_plain_channel_name(std::string(64, 'A')));
  EXPECT_THROW(lcm_channel_filter({std::string(64, 'A')}), std::invalid_argument);
}

}  // namespace
}  // namespace sg
