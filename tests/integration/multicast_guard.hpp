#pragma once

#include <gtest/gtest.h>

#include <string>

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

}  // namespace sg::test
