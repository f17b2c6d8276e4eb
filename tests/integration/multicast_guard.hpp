#pragma once

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

#include "common/bus.hpp"

namespace sg::test {

/// The udpm URL of a test's own port, on this host only (ttl=0).
inline std::string test_url(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

/// Fails the test with advice when this host cannot do multicast (no route for 224.0.0.0/4).
inline ::testing::AssertionResult multicast_available(int port) {
  try {
    Bus probe(test_url(port));
    return ::testing::AssertionSuccess();
  } catch (const BusError& e) {
    return ::testing::AssertionFailure()
           << e.what() << " -- run the tests through scripts/test.sh, or under "
           << "scripts/multicast.sh run ctest";
  }
}

/// Sends each of `datagrams` as one UDP datagram to the test bus on `port` (this host only),
/// from one socket (one sender), whatever they are: for tests of what a reader of the bus does
/// with bytes LCM would never send.
inline void send_raw_datagrams(int port, const std::vector<std::vector<uint8_t>>& datagrams) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  const unsigned char ttl = 0;
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
  sockaddr_in to{};
  to.sin_family = AF_INET, to.sin_port = htons(static_cast<uint16_t>(port));
  inet_pton(AF_INET, "239.255.76.67", &to.sin_addr);
  for (const std::vector<uint8_t>& d : datagrams)
    sendto(fd, d.data(), d.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  close(fd);
}

}  // namespace sg::test
