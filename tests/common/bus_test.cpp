// The bus wrapper: typed publish/subscribe, refusal of undecodable messages, clear URL errors.

#include "common/bus.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <thread>

#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "common/shutdown.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/wait.hpp"

namespace sg {
namespace {

using namespace std::chrono_literals;
using stereograsp::blob_t;
using stereograsp::point3_t;

std::string heard_host() {
  char name[256] = {};
  return gethostname(name, sizeof name - 1) == 0 ? name : "?";
}

point3_t make_point(int64_t utime, double x) {
  point3_t p{};
  p.utime = utime;
  p.visible = 1;
  p.position[0] = x;
  return p;
}

// A typed subscriber receives exactly what was published, with its channel and size.
TEST(Bus, TypedPublishSubscribeOverMemq) {
  Bus bus("memq://");
  std::vector<point3_t> received;
  std::vector<ReceiveInfo> infos;
  bus.subscribe<point3_t>("OBJECT_POSITION", [&](const point3_t& p, const ReceiveInfo& info) {
    received.push_back(p);
    infos.push_back(info);
  });
  ASSERT_TRUE(bus.publish("OBJECT_POSITION", make_point(1000, 0.25)));
  ASSERT_TRUE(bus.publish("OBJECT_POSITION", make_point(2000, -0.5)));
  EXPECT_TRUE(bus.handle(100ms));
  EXPECT_TRUE(bus.handle(100ms));
  EXPECT_FALSE(bus.handle(10ms)) << "nothing more to handle";
  ASSERT_EQ(received.size(), 2u);
  EXPECT_EQ(received[0].utime, 1000);
  EXPECT_DOUBLE_EQ(received[1].position[0], -0.5);
  EXPECT_EQ(infos[0].channel, "OBJECT_POSITION");
  EXPECT_EQ(infos[0].size, make_point(0, 0).getEncodedSize());
  EXPECT_GT(infos[0].recv_utime, 0);
}

// last_handed_utime() is read as publish() hands the bytes to LCM: after the call began, before
// it returned, and no later than the message's receipt (memq:// stamps it as LCM takes it); 0
// before any publish.
TEST(Bus, PublishRecordsWhenItHandedTheMessageToLcm) {
  Bus bus("memq://");
  EXPECT_EQ(bus.last_handed_utime(), 0);
  std::vector<ReceiveInfo> infos;
  bus.subscribe<point3_t>("OBJECT_POSITION",
                          [&](const point3_t&, const ReceiveInfo& info) { infos.push_back(info); });
  const int64_t before = now_utime();
  ASSERT_TRUE(bus.publish("OBJECT_POSITION", make_point(1000, 0.25)));
  const int64_t after = now_utime();
  EXPECT_GE(bus.last_handed_utime(), before);
  EXPECT_LE(bus.last_handed_utime(), after);
  ASSERT_TRUE(bus.handle(100ms));
  ASSERT_EQ(infos.size(), 1u);
  EXPECT_LE(bus.last_handed_utime(), infos[0].recv_utime);
}

// A subscription holds kQueueEverySample messages while its handler is busy, not LCM's 30: udpm
// drops what comes beyond a subscription's queue (memq:// does not, so this needs the network).
TEST(Bus, QueueHoldsEverySampleOfABurst) {
  ASSERT_TRUE(test::multicast_available(7970));
  Bus bus(test::test_url(7970));
  int samples = 0, frames = 0;
  bus.subscribe<point3_t>("OBJECT_POSITION",
                          [&](const point3_t&, const ReceiveInfo&) { ++samples; });
  bus.subscribe<blob_t>(
      "BLOB_LEFT", [&](const blob_t&, const ReceiveInfo&) { ++frames; }, kQueueFrames);
  for (int i = 0; i < kQueueEverySample + 44; ++i) {  // more than either queue holds
    bus.publish("OBJECT_POSITION", make_point(i, 0.0));
    bus.publish("BLOB_LEFT", blob_t{});
    if (i % 16 == 0) std::this_thread::sleep_for(1ms);  // within the kernel's socket buffer
  }
  // Once LCM's receive thread has read every datagram, each is queued or dropped.
  ASSERT_TRUE(test::wait_until([&] { return test::drained_bus(getpid(), 7970); }, 10s));
  std::this_thread::sleep_for(50ms);  // a datagram read is queued within microseconds
  while (bus.handle(50ms)) {
  }
  // LCM 1.3.1 keeps one message beyond the capacity it is given (so with both capacities here).
  EXPECT_EQ(samples, kQueueEverySample + 1);
  EXPECT_EQ(frames, kQueueFrames + 1);
  EXPECT_THROW(bus.subscribe<point3_t>(
                   "X", [](const point3_t&, const ReceiveInfo&) {}, 0),
               BusError);
}

// Channel patterns are regular expressions, as in LCM.
TEST(Bus, SubscribesByRegex) {
  Bus bus("memq://");
  std::vector<std::string> channels;
  bus.subscribe<blob_t>(
      "BLOB_.*", [&](const blob_t&, const ReceiveInfo& info) { channels.push_back(info.channel); });
  blob_t blob{};
  bus.publish("BLOB_LEFT", blob);
  bus.publish("BLOB_RIGHT", blob);
  bus.publish("OBJECT_POSITION", make_point(1, 1));
  while (bus.handle(10ms)) {
  }
  EXPECT_EQ(channels, (std::vector<std::string>{"BLOB_LEFT", "BLOB_RIGHT"}));
}

// Another type, a truncated message and trailing bytes are counted and dropped, never handed on.
TEST(Bus, UndecodableMessagesAreCountedAndDropped) {
  Bus bus("memq://");
  int calls = 0;
  bus.subscribe<point3_t>("OBJECT_POSITION", [&](const point3_t&, const ReceiveInfo&) { ++calls; });

  bus.publish("OBJECT_POSITION", blob_t{});  // wrong type
  std::vector<uint8_t> bytes(static_cast<size_t>(make_point(5, 1).getEncodedSize()));
  make_point(5, 1).encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  bus.publish_raw("OBJECT_POSITION", bytes.data(), static_cast<int>(bytes.size()) - 3);  // short
  bytes.push_back(0);
  bus.publish_raw("OBJECT_POSITION", bytes.data(), static_cast<int>(bytes.size()));  // long
  bytes.pop_back();
  bus.publish_raw("OBJECT_POSITION", bytes.data(), static_cast<int>(bytes.size()));  // good
  while (bus.handle(10ms)) {
  }
  EXPECT_EQ(bus.decode_errors(), 3u);
  EXPECT_EQ(calls, 1);
}

stereograsp::image_t make_image(int64_t utime, size_t bytes) {
  stereograsp::image_t m{};
  m.utime = utime;
  m.size = static_cast<int32_t>(bytes);
  m.data.resize(bytes);
  for (size_t i = 0; i < bytes; ++i) m.data[i] = static_cast<uint8_t>(i * 7 + utime);
  return m;
}

// A channel read directly arrives whole (a 300 kB image in fragments and a small one) with its
// channel, size and kernel time, beside a channel LCM delivers, and counts as received.
TEST(Bus, DirectChannelsArriveBesideLcmsOwn) {
  ASSERT_TRUE(test::multicast_available(7976));
  const std::string url = test::test_url(7976) + "&recv_buf_size=4194304";
  Bus bus(url), sender(url);
  std::vector<stereograsp::image_t> images;
  std::vector<ReceiveInfo> infos;
  int points = 0;
  EXPECT_TRUE(bus.subscribe_direct<stereograsp::image_t>(
      "CAMERA_LEFT", [&](const stereograsp::image_t& m, const ReceiveInfo& info) {
        images.push_back(m);
        infos.push_back(info);
      }));
  bus.subscribe<point3_t>("OBJECT_POSITION",
                          [&](const point3_t&, const ReceiveInfo&) { ++points; });
  const int64_t before = now_utime();
  sender.publish("CAMERA_LEFT", make_image(1, 300000));
  sender.publish("CAMERA_RIGHT", make_image(2, 300000));  // nobody's: skipped quietly
  sender.publish("OBJECT_POSITION", make_point(3, 0.5));
  sender.publish("CAMERA_LEFT", make_image(4, 100));
  ASSERT_TRUE(
      test::eventually([&] { return (bus.handle(20ms), images.size() == 2 && points == 1); }, 10s,
                       "two images read directly and a point from LCM"));
  EXPECT_EQ(images[0].data, make_image(1, 300000).data);
  EXPECT_EQ(images[1].data, make_image(4, 100).data);
  EXPECT_EQ(infos[0].channel, "CAMERA_LEFT");
  EXPECT_EQ(infos[0].size, make_image(1, 300000).getEncodedSize());
  EXPECT_GE(infos[0].recv_utime, before);
  EXPECT_LE(infos[0].recv_utime, now_utime());
  EXPECT_EQ(bus.messages_received(), 3u);
  EXPECT_EQ(bus.decode_errors(), 0u) << bus.last_problem();
  EXPECT_THROW(bus.subscribe_direct<stereograsp::image_t>(
                   "CAMERA_LEFT", [](const stereograsp::image_t&, const ReceiveInfo&) {}),
               BusError);
}

// Bytes that are not LCM's, a message of another type and a handler's exception on a channel read
// directly are each counted with a one-line reason; the next good message is served.
TEST(Bus, DirectChannelsCountWhatTheyRefuse) {
  ASSERT_TRUE(test::multicast_available(7977));
  Bus bus(test::test_url(7977)), sender(test::test_url(7977));
  int calls = 0;
  bus.subscribe_direct<stereograsp::image_t>(
      "CAMERA_LEFT", [&](const stereograsp::image_t& m, const ReceiveInfo&) {
        ++calls;
        if (m.utime == 5) throw std::runtime_error("a bad frame");
      });
  test::send_raw_datagrams(7977, {{'G', 'E', 'T', ' ', '/'}});
  ASSERT_TRUE(test::eventually([&] { return (bus.handle(20ms), bus.decode_errors() == 1); }, 10s,
                               "the datagram counted"));
  EXPECT_NE(bus.last_problem().find("not an LCM datagram (magic 0x47455420)"), std::string::npos)
      << bus.last_problem();
  EXPECT_EQ(bus.last_problem().rfind("bus datagram from ", 0), 0u) << bus.last_problem();
  sender.publish("CAMERA_LEFT", make_point(1, 0));  // another type
  sender.publish("CAMERA_LEFT", make_image(5, 10));
  sender.publish("CAMERA_LEFT", make_image(6, 10));
  ASSERT_TRUE(test::eventually([&] { return (bus.handle(20ms), calls == 2); }, 10s, "two images"));
  EXPECT_EQ(bus.decode_errors(), 2u) << bus.last_problem();
  EXPECT_EQ(bus.handler_errors(), 1u);
}

/// Threads in this process (entries of /proc/self/task).
size_t threads() {
  return static_cast<size_t>(std::distance(std::filesystem::directory_iterator("/proc/self/task"),
                                           std::filesystem::directory_iterator{}));
}

// A bus that reads its channels directly and has no LCM subscription never asks LCM for a
// message: handling starts no LCM receive thread (a second reader of every datagram on the
// group), and the channel read directly is still delivered.
TEST(Bus, DirectBusWithoutLcmSubscriptionsStartsNoLcmReceiveThread) {
  ASSERT_TRUE(test::multicast_available(7978));
  Bus bus(test::test_url(7978)), sender(test::test_url(7978));
  const size_t before = threads();
  int images = 0;
  ASSERT_TRUE(bus.subscribe_direct<stereograsp::image_t>(
      "CAMERA_LEFT", [&](const stereograsp::image_t&, const ReceiveInfo&) { ++images; }));
  sender.publish("CAMERA_LEFT", make_image(1, 1000));
  ASSERT_TRUE(test::eventually([&] { return (bus.handle(10ms), images == 1); }, 10s, "the image"));
  EXPECT_EQ(threads(), before);
}

// LCM's receive socket is filtered to the channels subscribed by name (each bus its own, two in
// one process), which still arrive; a pattern among the subscriptions lifts the filter, and
// what it matches arrives too.
TEST(Bus, LcmSocketFilteredToNamedChannelsUntilAPattern) {
  ASSERT_TRUE(test::multicast_available(7979));
  Bus a(test::test_url(7979)), b(test::test_url(7979)), sender(test::test_url(7979));
  EXPECT_FALSE(a.lcm_filtered());  // no subscription yet
  int points = 0, statuses = 0, blobs = 0;
  a.subscribe<point3_t>("OBJECT_POSITION", [&](const point3_t&, const ReceiveInfo&) { ++points; });
  b.subscribe<stereograsp::process_status_t>(
      "PROCESS_STATUS",
      [&](const stereograsp::process_status_t&, const ReceiveInfo&) { ++statuses; });
  EXPECT_TRUE(a.lcm_filtered());
  EXPECT_TRUE(b.lcm_filtered());
  sender.publish("CAMERA_LEFT", make_image(1, 1000));
  sender.publish("OBJECT_POSITION", make_point(2, 0.5));
  sender.publish("PROCESS_STATUS", stereograsp::process_status_t{});
  ASSERT_TRUE(test::eventually(
      [&] { return (a.handle(10ms), b.handle(10ms), points == 1 && statuses == 1); }, 10s,
      "each bus's channel"));
  a.subscribe<blob_t>("BLOB_(LEFT|RIGHT)", [&](const blob_t&, const ReceiveInfo&) { ++blobs; });
  EXPECT_FALSE(a.lcm_filtered());
  EXPECT_TRUE(b.lcm_filtered());
  sender.publish("BLOB_RIGHT", blob_t{});
  sender.publish("OBJECT_POSITION", make_point(3, 0.5));
  ASSERT_TRUE(test::eventually([&] { return (a.handle(10ms), blobs == 1 && points == 2); }, 10s,
                               "the pattern's channel and the named one"));
  EXPECT_EQ(a.decode_errors() + b.decode_errors(), 0u);
}

// On a bus that is not udpm:// a direct subscription is LCM's own, and still delivers.
TEST(Bus, DirectSubscriptionFallsBackToLcmOffUdpm) {
  Bus bus("memq://");
  int calls = 0;
  EXPECT_FALSE(bus.subscribe_direct<point3_t>(
      "OBJECT_POSITION", [&](const point3_t&, const ReceiveInfo&) { ++calls; }));
  bus.publish("OBJECT_POSITION", make_point(1, 0));
  EXPECT_TRUE(bus.handle(100ms));
  EXPECT_EQ(calls, 1);
}

// Unusable URLs throw one line that names the URL and LCM's reason.
TEST(Bus, BadUrlsThrowOneClearLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"bogus://x", "provider \"bogus\" not found"},
      {"udpm://300.1.1.1:7667", "Bad multicast IP address"},
      {"udpm://239.255.76.67:99999", "Bad multicast port"},
      {"file:///nonexistent/dir/x.log?mode=r", "No such file"},
      {"udpm://239.255.76.67:7667?ttl=abc", "Invalid value for ttl"},
      {"garbage", "invalid URL"},
  };
  for (const auto& [url, reason] : cases) {
    try {
      Bus bus(url);
      ADD_FAILURE() << url << " was accepted";
    } catch (const BusError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(url), std::string::npos) << what;
      EXPECT_NE(what.find(reason), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// spin() returns when the predicate says so, and when shutdown is requested.
TEST(Bus, SpinStopsOnPredicateAndOnShutdown) {
  Bus bus("memq://");
  int handled = 0;
  bus.subscribe<point3_t>("P", [&](const point3_t&, const ReceiveInfo&) { ++handled; });
  for (int i = 0; i < 5; ++i) bus.publish("P", make_point(i, 0));
  bus.spin([&] { return handled < 3; }, 10ms);
  EXPECT_EQ(handled, 3);
  request_shutdown();
  bus.spin([] { return true; }, 10ms);  // returns at once
  reset_shutdown();
  EXPECT_EQ(handled, 3);
}

// A file:// bus reads a log and reports its end.
TEST(Bus, FileUrlReportsEndOfLog) {
  const std::string path = "/tmp/sg-bus-test-" + std::to_string(getpid()) + ".lcmlog";
  {
    Bus writer("file://" + path + "?mode=w");
    writer.publish("OBJECT_POSITION", make_point(42, 1.0));
    writer.publish("OBJECT_POSITION", make_point(43, 2.0));
  }
  Bus reader("file://" + path + "?mode=r&speed=0");
  std::vector<int64_t> utimes;
  reader.subscribe<point3_t>(
      "OBJECT_POSITION", [&](const point3_t& p, const ReceiveInfo&) { utimes.push_back(p.utime); });
  reader.spin([] { return true; }, 100ms);
  EXPECT_TRUE(reader.end_of_log());
  EXPECT_EQ(utimes, (std::vector<int64_t>{42, 43}));
  std::remove(path.c_str());
}

// A file:// bus refuses a log whose event lengths LCM's reader would trust into a crash, with one
// line that says where.
TEST(Bus, FileUrlRefusesADamagedLog) {
  const std::string path = "/tmp/sg-bus-damaged-" + std::to_string(getpid()) + ".lcmlog";
  {
    Bus writer("file://" + path + "?mode=w");
    writer.publish("OBJECT_POSITION", make_point(42, 1.0));
  }
  const int64_t good_size = 28 + 15 + make_point(0, 0).getEncodedSize();
  {
    std::FILE* f = std::fopen(path.c_str(), "ab");
    // magic, event number 1, timestamp 0, channel length 15, data length 0x7fffffff
    const uint8_t header[28] = {0xED, 0xA1, 0xDA, 0x01, 0, 0, 0, 0, 0, 0,  0,    1,    0,    0,
                                0,    0,    0,    0,    0, 0, 0, 0, 0, 15, 0x7f, 0xff, 0xff, 0xff};
    std::fwrite(header, 1, sizeof header, f);
    std::fclose(f);
  }
  try {
    Bus reader("file://" + path + "?mode=r&speed=0");
    ADD_FAILURE() << "a damaged log was opened";
  } catch (const BusError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("damaged at byte " + std::to_string(good_size)), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  std::remove(path.c_str());
}

// A handler that throws does not end the process: the exception is caught before LCM's C code,
// counted, and the next message is served.
TEST(Bus, HandlerExceptionsAreCaughtCountedAndServingGoesOn) {
  Bus bus("memq://");
  int calls = 0;
  bus.subscribe<point3_t>("P", [&](const point3_t& p, const ReceiveInfo&) {
    ++calls;
    if (p.utime == 1) throw std::length_error("basic_string::_M_create");
    if (p.utime == 2) throw 42;
  });
  for (int i = 1; i <= 3; ++i) bus.publish("P", make_point(i, 0));
  while (bus.handle(10ms)) {
  }
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(bus.handler_errors(), 2u);
  EXPECT_EQ(bus.messages_received(), 3u);
  EXPECT_NE(bus.last_problem().find("P: handler failed"), std::string::npos) << bus.last_problem();
}

// The packet that aborted every process on main (an arm_cmd_t whose sender length is 0) is
// refused with its reason, and the subscriber is never called.
TEST(Bus, ZeroLengthStringIsRefusedNotFatal) {
  Bus bus("memq://");
  int calls = 0;
  bus.subscribe<stereograsp::arm_cmd_t>(
      "ARM_COMMAND", [&](const stereograsp::arm_cmd_t&, const ReceiveInfo&) { ++calls; });
  stereograsp::arm_cmd_t c{};
  c.sender = "x";
  std::vector<uint8_t> bytes = encode_message(c);
  const size_t at = bytes.size() - 40 - 2 - 4;
  bytes[at] = bytes[at + 1] = bytes[at + 2] = bytes[at + 3] = 0;
  bus.publish_raw("ARM_COMMAND", bytes.data(), static_cast<int>(bytes.size()));
  bus.publish("ARM_COMMAND", c);
  while (bus.handle(10ms)) {
  }
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(bus.decode_errors(), 1u);
  EXPECT_NE(bus.last_problem().find("'sender'"), std::string::npos) << bus.last_problem();
}

// An announced process publishes its counts on PROCESS_STATUS, and note_refused() counts there.
TEST(Bus, AnnouncedProcessPublishesItsCounts) {
  Bus bus("memq://");
  std::vector<stereograsp::process_status_t> statuses;
  bus.subscribe<stereograsp::process_status_t>(
      "PROCESS_STATUS",
      [&](const stereograsp::process_status_t& s, const ReceiveInfo&) { statuses.push_back(s); });
  bus.note_refused("OBJECT_POSITION", "x = 1e300 m is outside the workspace");
  bus.announce("sg-test");
  while (bus.handle(10ms)) {
  }
  ASSERT_EQ(statuses.size(), 1u) << "one at once, the next a second later";
  EXPECT_EQ(statuses[0].process, "sg-test");
  EXPECT_EQ(statuses[0].pid, static_cast<int32_t>(getpid()));
  EXPECT_EQ(statuses[0].refused_inputs, 1);
  EXPECT_EQ(statuses[0].last_problem,
            "OBJECT_POSITION: refused: x = 1e300 m is outside the workspace");
  EXPECT_FALSE(statuses[0].host.empty());
}

// Two announced processes on one host echo each other's heartbeats: each measures the other's
// clock (the same clock: offset 0) within the bound of its exchange, lists the channels it used
// with their counts, and reports STATE_STARTING until set_state() says it is ready.
TEST(Bus, AnnouncedProcessesMeasureEachOthersClock) {
  ASSERT_TRUE(test::multicast_available(7971));
  Bus a(test::test_url(7971)), b(test::test_url(7971));
  std::vector<stereograsp::process_status_t> heard;
  a.subscribe<stereograsp::process_status_t>(
      "PROCESS_STATUS",
      [&](const stereograsp::process_status_t& s, const ReceiveInfo&) { heard.push_back(s); });
  a.announce("sg-a");
  b.announce("sg-b", stereograsp::process_status_t::STATE_STARTING, "waiting for /dev/null");
  b.publish("OBJECT_POSITION", make_point(1, 0.5));
  auto known = [](const Bus& bus, const std::string& peer) {
    const auto o = bus.clock_sync()->offset(peer);
    return o && o->known;
  };
  const std::string name_a = "sg-a@" + heard_host() + ":" + std::to_string(getpid());
  const std::string name_b = "sg-b@" + heard_host() + ":" + std::to_string(getpid());
  ASSERT_TRUE(test::eventually(
      [&] {
        a.handle(10ms);
        b.handle(10ms);
        return known(a, name_b) && known(b, name_a);
      },
      10s, "both offsets measured"));
  const auto o = *a.clock_sync()->offset(name_b);
  EXPECT_LE(std::abs(o.offset_us), o.error_us) << "the same clock, within the exchange's bound";
  EXPECT_LT(o.error_us, 100'000);
  const auto from_b =
      std::find_if(heard.rbegin(), heard.rend(), [](auto& s) { return s.process == "sg-b"; });
  ASSERT_NE(from_b, heard.rend());
  EXPECT_EQ(from_b->state, stereograsp::process_status_t::STATE_STARTING);
  EXPECT_EQ(from_b->state_detail, "waiting for /dev/null");
  const auto row = std::find(from_b->channel.begin(), from_b->channel.end(), "OBJECT_POSITION");
  ASSERT_NE(row, from_b->channel.end());
  EXPECT_EQ(from_b->messages_out[static_cast<size_t>(row - from_b->channel.begin())], 1);
  b.set_state(stereograsp::process_status_t::STATE_READY);
  ASSERT_TRUE(test::eventually(
      a,
      [&] {
        return std::any_of(heard.begin(), heard.end(), [](auto& s) {
          return s.process == "sg-b" && s.state == stereograsp::process_status_t::STATE_READY;
        });
      },
      5s, "sg-b ready at once"));
}

}  // namespace
}  // namespace sg
