// Whose clock the forecast is on: the host publishing CAMERA_LEFT (else OBJECT_POSITION), from
// PROCESS_STATUS; its offset from the heartbeats' exchange; usable only when known closely.

#include "grasp/capture_clock.hpp"

#include <gtest/gtest.h>

namespace sg::grasp {
namespace {

using stereograsp::process_status_t;

constexpr int64_t kT0 = 1'700'000'000'000'000;

process_status_t status(const std::string& process, const std::string& host, int32_t pid,
                        int64_t utime, const std::string& publishes = "") {
  process_status_t s{};
  s.process = process;
  s.host = host;
  s.pid = pid;
  s.utime = utime;
  if (!publishes.empty()) {
    s.num_channels = 1;
    s.channel = {publishes};
    s.messages_in = {0};
    s.messages_out = {42};
    s.rate_in_hz = {0.0};
    s.rate_out_hz = {4.0};
  }
  return s;
}

/// sg-grasp on lab2 (pid 9) and sg-camera-sim on lab1, whose clock is `offset` ahead; one
/// exchange with one-way delays of `delay` µs. Returns the ClockSync of sg-grasp.
ClockSync exchange(int64_t offset, int64_t delay) {
  ClockSync grasp("sg-grasp@lab2:9");
  process_status_t mine = status("sg-grasp", "lab2", 9, kT0);
  grasp.fill(mine);  // t1
  process_status_t camera = status("sg-camera-sim", "lab1", 7, kT0 + offset + 500'000);
  camera.num_peers = 1;
  camera.peer = {"sg-grasp@lab2:9"};
  camera.peer_utime = {kT0};                        // t1
  camera.peer_recv_utime = {kT0 + offset + delay};  // t2, lab1's clock
  camera.peer_offset_us = {0};
  camera.peer_offset_error_us = {-1};
  grasp.receive(camera, kT0 + 500'000 + delay);  // t4, lab2's clock (t3 = camera.utime)
  return grasp;
}

// The camera publisher's host and offset, usable when the exchange was close.
TEST(CaptureClock, CameraHostOffsetFromTheExchange) {
  ProcessWatch watch;
  watch.receive(status("sg-camera-sim", "lab1", 7, kT0, "CAMERA_LEFT"), kT0);
  watch.receive(status("sg-vision", "lab3", 8, kT0, "OBJECT_POSITION"), kT0);
  const ClockSync sync = exchange(-800'000, 200);
  const auto e = CaptureClock::estimate(watch, sync, "lab2");
  EXPECT_TRUE(e.usable);
  EXPECT_EQ(e.host, "lab1");
  EXPECT_EQ(e.source, "sg-camera-sim@lab1:7 (CAMERA_LEFT)");
  EXPECT_EQ(e.offset_us, -800'000);
  EXPECT_EQ(e.error_us, 200);
}

// Without camera images on the bus, OBJECT_POSITION's publisher stamps the times; on this host
// the offset is 0; nothing heard, nothing known.
TEST(CaptureClock, VisionHostAndThisHost) {
  ProcessWatch watch;
  EXPECT_FALSE(CaptureClock::estimate(watch, ClockSync("x@lab2:1"), "lab2").usable);
  EXPECT_EQ(CaptureClock::estimate(watch, ClockSync("x@lab2:1"), "lab2").why, "");
  watch.receive(status("sg-vision", "lab2", 8, kT0, "OBJECT_POSITION"), kT0);
  const auto e = CaptureClock::estimate(watch, ClockSync("x@lab2:1"), "lab2");
  EXPECT_TRUE(e.usable);
  EXPECT_EQ(e.offset_us, 0);
}

// An offset not yet measured, or known only loosely, is not used, and says why.
TEST(CaptureClock, UnknownOrLooseOffsetIsNotUsed) {
  ProcessWatch watch;
  watch.receive(status("sg-camera-sim", "lab1", 7, kT0, "CAMERA_LEFT"), kT0);
  auto e = CaptureClock::estimate(watch, ClockSync("sg-grasp@lab2:9"), "lab2");
  EXPECT_FALSE(e.usable);
  EXPECT_EQ(e.why,
            "capture clock on lab1 (sg-camera-sim@lab1:7 (CAMERA_LEFT)): no clock exchange "
            "with it yet");
  e = CaptureClock::estimate(watch, exchange(300'000, 40'000), "lab2");
  EXPECT_FALSE(e.usable);
  EXPECT_EQ(e.why, "capture clock on lab1: offset +300.0 ms known only to ± 40.0 ms");
}

}  // namespace
}  // namespace sg::grasp
