// The termios serial port on a real pseudo-terminal: raw bytes in both directions (no XON/XOFF,
// no CR/LF translation, no signals), read time-outs, a vanished device reported as LinkDown, and
// clear errors for a missing path, a non-terminal, bad framing and an unsupported baud.

#include "arm_driver/serial_port.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/arm_commands.hpp"

namespace sg::arm {
namespace {

using Bytes = std::vector<uint8_t>;
using std::chrono::milliseconds;

/// The master side of a pseudo-terminal; the port under test opens slave_path.
class Pty {
 public:
  Pty() {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0) return;
    const char* name = ::ptsname(master_);
    if (name != nullptr) slave_path_ = name;
  }
  ~Pty() { close_master(); }
  Pty(const Pty&) = delete;
  Pty& operator=(const Pty&) = delete;

  bool ok() const { return master_ >= 0 && !slave_path_.empty(); }
  const std::string& slave_path() const { return slave_path_; }

  void close_master() {
    if (master_ >= 0) ::close(master_);
    master_ = -1;
  }

  bool write(const Bytes& bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(master_, bytes.data() + done, bytes.size() - done);
      if (n <= 0) return false;
      done += static_cast<size_t>(n);
    }
    return true;
  }

  /// Up to `count` bytes, giving up after `timeout` without a byte.
  Bytes read(size_t count, milliseconds timeout) {
    Bytes bytes;
    while (bytes.size() < count) {
      pollfd p{master_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0 || !(p.revents & POLLIN)) break;
      uint8_t buffer[512];
      const ssize_t n = ::read(master_, buffer, std::min(sizeof buffer, count - bytes.size()));
      if (n <= 0) break;
      bytes.insert(bytes.end(), buffer, buffer + n);
    }
    return bytes;
  }

 private:
  int master_ = -1;
  std::string slave_path_;
};

/// Every byte value 0x00..0xFF, the control bytes (NUL, ^C, ^D, XON, XOFF, CR, LF, DEL) included.
Bytes every_byte() {
  Bytes bytes(256);
  std::iota(bytes.begin(), bytes.end(), 0);
  return bytes;
}

/// Reads `count` bytes from the port, each within a generous time-out; stops at the first miss.
Bytes read_port(SerialPort& port, size_t count) {
  Bytes bytes;
  while (bytes.size() < count) {
    const auto byte = port.read_byte(milliseconds(2000));
    if (!byte) break;
    bytes.push_back(*byte);
  }
  return bytes;
}

using test::message_of;

class SerialPortTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(pty.ok()) << "no pseudo-terminal available";
    port = SerialPort::open(pty.slave_path(), {});
    ASSERT_NE(port, nullptr);
  }
  Pty pty;
  std::unique_ptr<SerialPort> port;
};

// The port remembers the path it opened.
TEST_F(SerialPortTest, RemembersItsPath) { EXPECT_EQ(port->path(), pty.slave_path()); }

// Bytes the port writes arrive unchanged at the master: 0x00, XON, XOFF, CR, LF, 0xFF and all.
TEST_F(SerialPortTest, WritesEveryByteValueUnchanged) {
  const Bytes sent = every_byte();
  port->write(sent);
  EXPECT_EQ(pty.read(sent.size(), milliseconds(2000)), sent);
}

// Bytes written at the master reach the port unchanged: no XON/XOFF flow control eats 0x11 or
// 0x13, CR is not turned into LF, ^C raises no signal.
TEST_F(SerialPortTest, ReadsEveryByteValueUnchanged) {
  const Bytes sent = every_byte();
  ASSERT_TRUE(pty.write(sent));
  EXPECT_EQ(read_port(*port, sent.size()), sent);
  EXPECT_EQ(port->read_byte(milliseconds(20)), std::nullopt);
}

// The bytes the C550 protocol most depends on, both ways, one at a time.
TEST_F(SerialPortTest, PassesProtocolBytesBothWays) {
  for (const uint8_t byte : {0x00, 0x11, 0x13, 0xFF, 0x0D, 0x0A, 0x03, 0x1A}) {
    port->write(Bytes{byte});
    EXPECT_EQ(pty.read(1, milliseconds(2000)), Bytes{byte}) << "port -> master " << int{byte};
    ASSERT_TRUE(pty.write(Bytes{byte}));
    EXPECT_EQ(port->read_byte(milliseconds(2000)), byte) << "master -> port " << int{byte};
  }
}

// Nothing sent: read_byte waits about its time-out and returns nullopt (lower bound only).
TEST_F(SerialPortTest, ReadTimesOut) {
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(port->read_byte(milliseconds(60)), std::nullopt);
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_GE(waited, milliseconds(50));
}

// discard_input drops bytes that have arrived and not been read.
TEST_F(SerialPortTest, DiscardInputDropsPendingBytes) {
  ASSERT_TRUE(pty.write(Bytes{'a', 'b', 'c'}));
  ASSERT_EQ(port->read_byte(milliseconds(2000)), 'a');  // 'b' and 'c' are now buffered or queued
  port->discard_input();
  EXPECT_EQ(port->read_byte(milliseconds(20)), std::nullopt);
  ASSERT_TRUE(pty.write(Bytes{'d'}));
  EXPECT_EQ(port->read_byte(milliseconds(2000)), 'd');
}

// Closing the master (the device vanishing) makes a read throw LinkDown naming the path, and
// keeps throwing rather than inventing bytes.
TEST_F(SerialPortTest, ReadAfterHangUpThrowsLinkDown) {
  pty.close_master();
  const std::string message = message_of<LinkDown>([&] { port->read_byte(milliseconds(500)); });
  EXPECT_NE(message.find(pty.slave_path()), std::string::npos) << message;
  EXPECT_THROW(port->read_byte(milliseconds(500)), LinkDown);
}

// A hang-up after some bytes were read is still reported, not answered from a stale buffer.
TEST_F(SerialPortTest, ReadAfterHangUpFollowingDataThrowsLinkDown) {
  ASSERT_TRUE(pty.write(Bytes{'x'}));
  ASSERT_EQ(port->read_byte(milliseconds(2000)), 'x');
  pty.close_master();
  EXPECT_THROW(port->read_byte(milliseconds(500)), LinkDown);
  EXPECT_THROW(port->read_byte(milliseconds(500)), LinkDown);
}

// Closing the master makes a write throw LinkDown.
TEST_F(SerialPortTest, WriteAfterHangUpThrowsLinkDown) {
  pty.close_master();
  EXPECT_THROW(port->write(Bytes{'N', 'O', 'H'}), LinkDown);
}

// A missing device: the error names the path.
TEST(SerialPortOpenTest, MissingPathNamesThePath) {
  const std::string path = "/dev/no-such-serial-port-for-stereograsp";
  const std::string message =
      message_of<std::runtime_error>([&] { SerialPort::open(path, SerialSettings{}); });
  EXPECT_NE(message.find("cannot open " + path), std::string::npos) << message;
}

// A file that is not a terminal is refused with a message naming it.
TEST(SerialPortOpenTest, NonTerminalIsRefused) {
  const std::string message =
      message_of<std::runtime_error>([] { SerialPort::open("/dev/null", SerialSettings{}); });
  EXPECT_NE(message.find("/dev/null is not a serial device"), std::string::npos) << message;
}

// An unsupported baud rate is refused; the message names the path and the rate.
TEST(SerialPortOpenTest, UnsupportedBaudIsRefused) {
  Pty pty;
  ASSERT_TRUE(pty.ok());
  SerialSettings settings;
  settings.baud = 12345;
  const std::string message =
      message_of<std::runtime_error>([&] { SerialPort::open(pty.slave_path(), settings); });
  EXPECT_NE(message.find(pty.slave_path()), std::string::npos) << message;
  EXPECT_NE(message.find("unsupported baud rate 12345"), std::string::npos) << message;
}

// Other framings can be set on a terminal: 7E1 and 8O2 at 9600 and 115200 open.
TEST(SerialPortOpenTest, OpensWithOtherFramings) {
  Pty pty;
  ASSERT_TRUE(pty.ok());
  SerialSettings settings;
  settings.baud = 9600;
  parse_framing("7E1", settings);
  EXPECT_NE(SerialPort::open(pty.slave_path(), settings), nullptr);
  settings.baud = 115200;
  parse_framing("8O2", settings);
  EXPECT_NE(SerialPort::open(pty.slave_path(), settings), nullptr);
}

// describe() gives the settings as a log shows them.
TEST(SerialSettingsTest, Describe) {
  EXPECT_EQ(describe(SerialSettings{}), "38400 8N1");
  EXPECT_EQ(describe(SerialSettings{.baud = 9600, .data_bits = 7, .parity = 'E', .stop_bits = 2}),
            "9600 7E2");
}

// "8N1", "7E1" and "8O2" set data bits, parity and stop bits.
TEST(SerialSettingsTest, ParseFramingAccepts) {
  SerialSettings s;
  parse_framing("8N1", s);
  EXPECT_EQ(s.data_bits, 8);
  EXPECT_EQ(s.parity, 'N');
  EXPECT_EQ(s.stop_bits, 1);
  parse_framing("7E1", s);
  EXPECT_EQ(s.data_bits, 7);
  EXPECT_EQ(s.parity, 'E');
  EXPECT_EQ(s.stop_bits, 1);
  parse_framing("8O2", s);
  EXPECT_EQ(s.data_bits, 8);
  EXPECT_EQ(s.parity, 'O');
  EXPECT_EQ(s.stop_bits, 2);
  EXPECT_EQ(s.baud, 38400);  // untouched
}

// "9N1", "8X1", "8N3", "8N1x" and "" are refused with a message quoting the text; the settings
// are left as they were.
TEST(SerialSettingsTest, ParseFramingRejects) {
  for (const std::string text : {"9N1", "8X1", "8N3", "8N1x", ""}) {
    SerialSettings s;
    const std::string message = message_of<std::invalid_argument>([&] { parse_framing(text, s); });
    EXPECT_NE(message.find("serial framing '" + text + "' is not like 8N1"), std::string::npos)
        << message;
    EXPECT_EQ(describe(s), "38400 8N1") << text;
  }
}

}  // namespace
}  // namespace sg::arm
