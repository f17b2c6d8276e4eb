// The bus probes on real processes: joined_bus() says a process has subscribed on a udpm port
// (and not on another), drained_bus() that it has read what reached it, idle() that none of its
// threads has work.

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
constexpr int kPort = 7930;

// This test joins its port when it subscribes; its children hold none of its sockets: `sleep`
// never joins, sg-bus-check receive does, on its port and not on another.
TEST(JoinedBus, TrueOnceAProcessHasSubscribedOnThePort) {
  ASSERT_TRUE(multicast_available(kPort));
  Bus bus(test_url(kPort));
  EXPECT_FALSE(joined_bus(getpid(), kPort)) << "LCM binds its socket at the first subscribe";
  bus.subscribe_raw("ANY", [](const RawMessage&) {});
  EXPECT_TRUE(joined_bus(getpid(), kPort));

  Child idle({"sleep", "30"});
  Child receiver({program("sg-bus-check"), "receive", "--count", "1", "--timeout", "30",
                  "--lcm-url", test_url(kPort)});
  EXPECT_TRUE(eventually([&] { return joined_bus(receiver.pid(), kPort); }, 30s,
                         "sg-bus-check to join port 7930"));
  EXPECT_FALSE(joined_bus(receiver.pid(), kPort + 1));
  EXPECT_TRUE(idle.running());
  EXPECT_FALSE(joined_bus(idle.pid(), kPort));
}

// A stopped receiver leaves a message in its socket (not drained); continued, it reads it.
TEST(DrainedBus, FalseWhileAMessageWaitsInTheSocket) {
  ASSERT_TRUE(multicast_available(kPort + 2));
  Child receiver({program("sg-bus-check"), "receive", "--count", "1", "--timeout", "30",
                  "--lcm-url", test_url(kPort + 2)});
  ASSERT_TRUE(eventually([&] { return joined_bus(receiver.pid(), kPort + 2); }, 30s,
                         "sg-bus-check to join port 7932"));
  // LCM's self-test message, which the receiver sends itself on opening the bus, read.
  EXPECT_TRUE(eventually([&] { return drained_bus(receiver.pid(), kPort + 2); }, 10s,
                         "the receiver to read its own self-test message"));
  receiver.signal(SIGSTOP);
  // Published before the stop took effect, the message is read at once (seen in a CI run).
  ASSERT_TRUE(eventually([&] { return stopped(receiver.pid()); }, 10s, "the receiver to stop"));
  Bus bus(test_url(kPort + 2));
  const uint8_t byte = 1;
  bus.publish_raw("OTHER", &byte, 1);
  EXPECT_TRUE(eventually([&] { return !drained_bus(receiver.pid(), kPort + 2); }, 10s,
                         "the message to wait in the stopped receiver's socket"));
  receiver.signal(SIGCONT);
  EXPECT_TRUE(eventually([&] { return drained_bus(receiver.pid(), kPort + 2); }, 30s,
                         "the receiver to read it"));
  EXPECT_FALSE(drained_bus(receiver.pid(), kPort)) << "no socket on that port";
}

// `sleep` sleeps; a shell in a busy loop is runnable; an exited process is not idle.
TEST(Idle, TrueOnlyWhenEveryThreadSleeps) {
  Child sleeping({"sleep", "30"});
  EXPECT_TRUE(eventually([&] { return idle(sleeping.pid()); }, 10s, "`sleep` to sleep"));
  Child busy({"sh", "-c", "while :; do :; done"});
  int idle_seen = 0;
  for (int k = 0; k < 10; ++k) idle_seen += idle(busy.pid()) ? 1 : 0;
  EXPECT_EQ(idle_seen, 0) << "a busy loop is never seen asleep twice 20 ms apart";
  busy.signal(SIGKILL);
  busy.wait(10s);
  EXPECT_FALSE(idle(busy.pid()));
}

// A process is stopped once SIGSTOP has taken effect, and no longer once continued.
TEST(Stopped, TrueOnlyWhileEveryThreadIsStopped) {
  Child sleeping({"sleep", "30"});
  EXPECT_FALSE(stopped(sleeping.pid()));
  sleeping.signal(SIGSTOP);
  EXPECT_TRUE(eventually([&] { return stopped(sleeping.pid()); }, 10s, "`sleep` to stop"));
  sleeping.signal(SIGCONT);
  EXPECT_TRUE(eventually([&] { return !stopped(sleeping.pid()); }, 10s, "`sleep` to go on"));
}

}  // namespace
}  // namespace sg::test
