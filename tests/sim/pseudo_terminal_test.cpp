// The pseudo-terminal sg-c550-sim offers: it opens, a symlink points at it, bytes go both ways.

#include "sim/pseudo_terminal.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "tests/support/subprocess.hpp"

namespace sg::sim {
namespace {

/// Reads `n` bytes from `fd`, waiting up to 2 s for them.
std::string read_bytes(int fd, size_t n) {
  std::string out;
  while (out.size() < n) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 2000) <= 0) break;
    char buffer[64];
    const ssize_t got = ::read(fd, buffer, std::min(sizeof buffer, n - out.size()));
    if (got <= 0) break;
    out.append(buffer, static_cast<size_t>(got));
  }
  return out;
}

// The slave device exists, is a terminal, and carries bytes raw (no echo, no CR/LF mapping)
// from the master to a driver that opened it and back.
TEST(PseudoTerminal, CarriesBytesBothWays) {
  PseudoTerminal pty;
  ASSERT_TRUE(std::filesystem::exists(pty.path())) << pty.path();
  const int driver = ::open(pty.path().c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(driver, 0);
  EXPECT_TRUE(::isatty(driver));
  const std::string to_driver = std::string("W2\r\n\x05\x00\xff", 7);
  ASSERT_EQ(::write(pty.master(), to_driver.data(), to_driver.size()), 7);
  EXPECT_EQ(read_bytes(driver, 7), to_driver);
  const std::string to_controller = std::string("\x06\r\x15", 3);
  ASSERT_EQ(::write(driver, to_controller.data(), to_controller.size()), 3);
  EXPECT_EQ(read_bytes(pty.master(), 3), to_controller);
  ::close(driver);
}

// With no driver attached, reading the master does not fail (the simulator holds a slave fd).
TEST(PseudoTerminal, MasterReadsNothingWithoutADriver) {
  PseudoTerminal pty;
  char byte;
  EXPECT_EQ(::read(pty.master(), &byte, 1), -1);
  EXPECT_TRUE(errno == EAGAIN || errno == EWOULDBLOCK) << errno;
}

// The symlink points at the pseudo-terminal, follows a new one, and is removed at the end.
TEST(Symlink, PointsFollowsAndIsRemoved) {
  const std::string link = test::make_temp_dir() + "/c550";
  PseudoTerminal first, second;
  {
    Symlink symlink(link);
    symlink.point_to(first.path());
    EXPECT_EQ(std::filesystem::read_symlink(link).string(), first.path());
    symlink.point_to(second.path());
    EXPECT_EQ(std::filesystem::read_symlink(link).string(), second.path());
  }
  EXPECT_FALSE(std::filesystem::is_symlink(link));
}

// A link that someone else re-pointed is left alone.
TEST(Symlink, LeavesAnotherTargetAlone) {
  const std::string link = test::make_temp_dir() + "/c550";
  PseudoTerminal pty;
  Symlink symlink(link);
  symlink.point_to(pty.path());
  std::filesystem::remove(link);
  std::filesystem::create_symlink("/dev/null", link);
  symlink.remove();
  EXPECT_EQ(std::filesystem::read_symlink(link).string(), "/dev/null");
}

}  // namespace
}  // namespace sg::sim
