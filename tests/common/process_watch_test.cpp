// Who is on the bus: processes joining, stopping cleanly, falling silent and coming back, judged
// by the watcher's receive times; host clock offsets from the offsets the processes publish; and
// per-channel counts and rates.

#include "common/process_watch.hpp"

#include <gtest/gtest.h>

#include "common/channel_rates.hpp"

namespace sg {
namespace {

using stereograsp::process_status_t;

process_status_t status(const std::string& process, const std::string& host, int32_t pid,
                        int64_t utime, int8_t state = process_status_t::STATE_READY) {
  process_status_t s{};
  s.process = process;
  s.host = host;
  s.pid = pid;
  s.utime = utime;
  s.state = state;
  return s;
}

constexpr int64_t kT0 = 1'700'000'000'000'000;

// A process that joins is reported once; one silent for 2.5 s is reported as stopped beating,
// judged by receive times even when its own clock is an hour off; its return is reported.
TEST(ProcessWatch, SilenceIsJudgedByReceiveTime) {
  ProcessWatch watch;
  const int64_t skew = 3'600'000'000;
  for (int k = 0; k < 3; ++k)
    watch.receive(status("sg-vision", "lab1", 7, kT0 + skew + k * 1'000'000), kT0 + k * 1'000'000);
  auto events = watch.check(kT0 + 2'000'000);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ProcessWatch::Event::kJoined);
  EXPECT_EQ(events[0].name, "sg-vision@lab1:7");
  EXPECT_TRUE(watch.check(kT0 + 4'400'000).empty()) << "2.4 s of silence is not yet a stop";
  events = watch.check(kT0 + 4'600'000);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ProcessWatch::Event::kStoppedBeating);
  EXPECT_EQ(events[0].line, "sg-vision@lab1:7 stopped beating (silent 2.6 s)");
  EXPECT_TRUE(watch.check(kT0 + 9'000'000).empty()) << "reported once";
  watch.receive(status("sg-vision", "lab1", 7, kT0), kT0 + 10'000'000);
  events = watch.check(kT0 + 10'000'000);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ProcessWatch::Event::kBack);
}

// A process whose last status says it is stopping has stopped cleanly, not fallen silent.
TEST(ProcessWatch, CleanStopIsNotSilence) {
  ProcessWatch watch;
  watch.receive(status("sg-grasp", "lab2", 9, kT0), kT0);
  watch.receive(status("sg-grasp", "lab2", 9, kT0 + 1, process_status_t::STATE_STOPPING), kT0 + 1);
  auto events = watch.check(kT0 + 10'000'000);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, ProcessWatch::Event::kJoined);
  EXPECT_EQ(events[1].kind, ProcessWatch::Event::kStopped);
  EXPECT_EQ(state_name(watch.find("sg-grasp")->last.state), "stopping");
}

// Host offsets to the reference host come from either side's published measurement, the one of
// least error kept; the reference itself is 0.
TEST(ProcessWatch, HostOffsetsFromThePublishedMeasurements) {
  ProcessWatch watch;
  process_status_t grasp = status("sg-grasp", "lab2", 9, kT0);
  grasp.num_peers = 2;
  grasp.peer = {"sg-vision@lab1:7", "sg-arm-driver@lab3:5"};
  grasp.peer_utime = grasp.peer_recv_utime = {0, 0};
  grasp.peer_offset_us = {-800'000, 120};
  grasp.peer_offset_error_us = {900, 400};
  process_status_t vision = status("sg-vision", "lab1", 7, kT0);
  vision.num_peers = 1;
  vision.peer = {"sg-grasp@lab2:9"};
  vision.peer_utime = vision.peer_recv_utime = {0};
  vision.peer_offset_us = {800'100};  // lab2 - lab1, measured by lab1 more closely
  vision.peer_offset_error_us = {150};
  watch.receive(grasp, kT0);
  watch.receive(vision, kT0);
  watch.receive(status("sg-arm-driver", "lab3", 5, kT0), kT0);
  const auto offsets = watch.host_offsets("lab2");
  ASSERT_EQ(offsets.size(), 3u);
  EXPECT_EQ(offsets[0].host, "lab2");
  EXPECT_EQ(offsets[0].offset_us, 0);
  EXPECT_EQ(offsets[1].host, "lab1");
  EXPECT_EQ(offsets[1].offset_us, -800'100);
  EXPECT_EQ(offsets[1].error_us, 150);
  EXPECT_EQ(offsets[2].host, "lab3");
  EXPECT_EQ(offsets[2].offset_us, 120);
}

// However many processes a hostile host invents, the watch holds kMaxProcesses.
TEST(ProcessWatch, TableIsBounded) {
  ProcessWatch watch;
  for (int i = 0; i < 5000; ++i) watch.receive(status("x", "h", i, 0), kT0 + i);
  EXPECT_EQ(watch.processes().size(), ProcessWatch::kMaxProcesses);
  EXPECT_EQ(watch.processes().back().name, "x@h:4999");
}

// Counts per channel, rates over the interval between fills, and one "(other)" row beyond 63.
TEST(ChannelRates, CountsRatesAndTheOtherRow) {
  ChannelRates rates;
  process_status_t s{};
  rates.sent("OBJECT_TRAJECTORY");
  rates.fill(s, 10.0);
  ASSERT_EQ(s.num_channels, 1);
  EXPECT_EQ(s.messages_out[0], 1);
  EXPECT_EQ(s.rate_out_hz[0], 0.0) << "no interval yet";
  for (int i = 0; i < 8; ++i) rates.received("OBJECT_POSITION");
  for (int i = 0; i < 4; ++i) rates.sent("OBJECT_TRAJECTORY");
  rates.fill(s, 12.0);
  ASSERT_EQ(s.num_channels, 2);
  EXPECT_EQ(s.channel[1], "OBJECT_POSITION");
  EXPECT_DOUBLE_EQ(s.rate_in_hz[1], 4.0);
  EXPECT_DOUBLE_EQ(s.rate_out_hz[0], 2.0);
  EXPECT_EQ(s.messages_out[0], 5);
  for (int i = 0; i < 1000; ++i) rates.received("JUNK_" + std::to_string(i));
  rates.fill(s, 13.0);
  ASSERT_EQ(s.num_channels, static_cast<int32_t>(ChannelRates::kMaxChannels));
  EXPECT_EQ(s.channel.back(), "(other)");
  EXPECT_EQ(s.messages_in.back(), 1000 - 61);
}

}  // namespace
}  // namespace sg
