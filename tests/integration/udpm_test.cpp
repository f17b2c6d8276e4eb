// Two separate processes exchange messages over udpm:// on a port of the test's own.

#include <gtest/gtest.h>

#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;

// 1,000 messages of all nine types at 100 Hz arrive, none lost, every byte intact.
TEST(Udpm, ThousandMessagesAt100HzBetweenProcessesNoneLost) {
  constexpr int kPort = 7901;
  ASSERT_TRUE(multicast_available(kPort));
  const std::string url = test_url(kPort);
  Child receiver(
      {program("sg-bus-check"), "receive", "--count", "1000", "--timeout", "10", "--lcm-url", url});
  ASSERT_TRUE(eventually([&] { return listening_on_bus(receiver.pid(), kPort); }, 30s,
                         "the receiver to join the bus"));
  const ProcessResult sender = run(
      {program("sg-bus-check"), "send", "--count", "1000", "--rate", "100", "--lcm-url", url}, 60s);
  ASSERT_EQ(sender.exit_code, 0) << sender.err;
  EXPECT_NE(sender.out.find("sent 1000 messages of 10 types"), std::string::npos) << sender.out;
  const ProcessResult received = receiver.wait(30s);
  EXPECT_FALSE(received.timed_out);
  EXPECT_EQ(received.exit_code, 0) << received.out << received.err;
  EXPECT_NE(received.out.find("received 1000 of 1000 (0 lost) on 10 channels"), std::string::npos)
      << received.out;
  EXPECT_NE(received.out.find("0 corrupt, 0 duplicate"), std::string::npos) << received.out;
}

// A receiver that hears nothing reports the loss and fails, so the test above can fail.
TEST(Udpm, SilenceIsReportedAsLoss) {
  constexpr int kPort = 7904;
  ASSERT_TRUE(multicast_available(kPort));
  const ProcessResult received = run({program("sg-bus-check"), "receive", "--count", "10",
                                      "--timeout", "1", "--lcm-url", test_url(kPort)},
                                     20s);
  EXPECT_EQ(received.exit_code, 1);
  EXPECT_NE(received.out.find("received 0 of 10 (10 lost)"), std::string::npos) << received.out;
}

}  // namespace
}  // namespace sg::test
