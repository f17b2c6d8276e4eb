// The stock lcm-logger records a stream that lcm::LogFile reads back exactly as sent, and the
// stock lcm-logplayer replays it to a subscriber.

#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>

#include "common/bus.hpp"
#include "common/bus_check.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

constexpr int kCount = 270;  // 30 messages of each of the 9 types

class LoggerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ASSERT_TRUE(multicast_available(7902));
    dir_ = make_temp_dir();
    log_path_ = dir_ + "/session.lcmlog";
    Child logger({SG_LCM_LOGGER, "--lcm-url=" + test_url(7902), "-c", "BUS_CHECK_.*", log_path_});
    ASSERT_TRUE(eventually([&] { return listening_on_bus(logger.pid(), 7902); }, 30s,
                           "lcm-logger to join the bus"));
    Bus observer(test_url(7902));  // hears what the logger hears
    int heard = 0;
    observer.subscribe_raw("BUS_CHECK_.*", [&](const RawMessage&) { ++heard; });
    Child sending({program("sg-bus-check"), "send", "--count", std::to_string(kCount), "--rate",
                   "200", "--lcm-url", test_url(7902)});
    wait_until(
        observer, [&] { return !sending.running(); }, 60s);  // reading what it sends
    const ProcessResult sender = sending.wait(1s);
    ASSERT_EQ(sender.exit_code, 0) << sender.err;
    // Stop lcm-logger once every message has reached it and it has handled them all.
    ASSERT_TRUE(eventually(
        observer, [&] { return heard >= kCount && handled_bus(logger.pid(), 7902); }, 30s,
        "lcm-logger to read all " + std::to_string(kCount) + " messages"));
    logger.signal(SIGINT);
    const ProcessResult stopped = logger.wait(10s);
    ASSERT_FALSE(stopped.timed_out) << "lcm-logger did not stop on SIGINT";
  }

  static std::string dir_;
  static std::string log_path_;
};
std::string LoggerTest::dir_;
std::string LoggerTest::log_path_;

// Every event in the log is a message as sent, in order, and none is missing.
TEST_F(LoggerTest, LogFileReadsBackExactlyWhatWasSent) {
  lcm::LogFile log(log_path_, "r");
  ASSERT_TRUE(log.good());
  int events = 0;
  int64_t last_utime = 0;
  int64_t last_timestamp = 0;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    const auto verdict =
        bus_check::verify(event->channel, static_cast<const uint8_t*>(event->data), event->datalen);
    ASSERT_TRUE(verdict.has_value()) << event->channel;
    EXPECT_TRUE(verdict->intact) << "event " << events;
    EXPECT_EQ(verdict->type_index, events % bus_check::type_count()) << "sent in this order";
    EXPECT_GT(verdict->utime, last_utime) << "sent in this order";
    // Receive times are wall-clock stamps, not a monotonic clock's: a loaded sanitized run saw one
    // 0.9 ms before the one logged ahead of it (the datagrams themselves in order). In order, to
    // within 5 ms.
    EXPECT_GE(event->timestamp, last_timestamp - 5000) << "receive times in order";
    EXPECT_GE(event->timestamp, verdict->utime) << "received after it was sent";
    last_utime = verdict->utime;
    last_timestamp = event->timestamp;
    ++events;
  }
  EXPECT_EQ(events, kCount);
}

// sg-bus-check verify-log agrees, and a log cut in the middle of an event is read up to the cut
// and reported short, without a crash.
TEST_F(LoggerTest, VerifyLogAcceptsTheLogAndReportsATruncatedOne) {
  const ProcessResult whole =
      run({program("sg-bus-check"), "verify-log", log_path_, "--count", std::to_string(kCount)});
  EXPECT_EQ(whole.exit_code, 0) << whole.out << whole.err;

  const std::string cut = dir_ + "/cut.lcmlog";
  fs::copy_file(log_path_, cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(log_path_) / 2 + 7);  // mid-event, almost surely
  const ProcessResult truncated =
      run({program("sg-bus-check"), "verify-log", cut, "--count", std::to_string(kCount)});
  EXPECT_EQ(truncated.exit_code, 1) << truncated.out;
  EXPECT_NE(truncated.out.find("lost)"), std::string::npos) << truncated.out;
  EXPECT_NE(truncated.out.find("0 corrupt"), std::string::npos) << truncated.out;
}

// lcm-logplayer replays the log onto another port, where a subscriber gets every message.
TEST_F(LoggerTest, LogplayerReplaysToASubscriber) {
  ASSERT_TRUE(multicast_available(7903));
  Child receiver({program("sg-bus-check"), "receive", "--count", std::to_string(kCount),
                  "--timeout", "10", "--lcm-url", test_url(7903)});
  ASSERT_TRUE(eventually([&] { return listening_on_bus(receiver.pid(), 7903); }, 30s,
                         "the receiver to join the bus"));
  const ProcessResult player =
      run({SG_LCM_LOGPLAYER, "-s", "4", "-l", test_url(7903), log_path_}, 60s);
  EXPECT_EQ(player.exit_code, 0) << player.err;
  const ProcessResult received = receiver.wait(30s);
  EXPECT_EQ(received.exit_code, 0) << received.out << received.err;
  EXPECT_NE(received.out.find("received " + std::to_string(kCount) + " of " +
                              std::to_string(kCount) + " (0 lost)"),
            std::string::npos)
      << received.out;
}

}  // namespace
}  // namespace sg::test
