// sg-predictor as a process: live, and replayed from the real lcm-logger's log through the real
// lcm-logplayer, it publishes byte-identical trajectories; training from that log; bad input.

#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <thread>

#include "common/bus.hpp"
#include "common/message_types.hpp"
#include "sim/scenario.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<uint8_t>;

/// Subscribes to OBJECT_TRAJECTORY (before anything is started that could publish).
void listen(Bus& bus, std::vector<Bytes>& out) {
  bus.subscribe_raw("OBJECT_TRAJECTORY", [&out](const RawMessage& m) {
    out.emplace_back(m.data, m.data + m.info.size);
  });
}

/// Handles messages until `out` holds `count` or a timeout.
void collect(
    Bus& bus, const std::vector<Bytes>& out, size_t count, std::chrono::seconds timeout,
    const std::function<void()>& between = [] {}) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (out.size() < count && std::chrono::steady_clock::now() < deadline) {
    between();
    bus.handle(20ms);
  }
  while (bus.handle(300ms)) {
  }
}

TEST(Predictor, ReplayedLogGivesIdenticalTrajectories) {
  ASSERT_TRUE(multicast_available(7914));
  ASSERT_TRUE(multicast_available(7915));
  const std::string dir = make_temp_dir();
  const std::string log = dir + "/session.lcmlog";
  // Capture times of 2023 (so a replay is the same): the gate on the receiver's clock is off.
  Child live({program("sg-predictor"), "--lcm-url", test_url(7914), "--max-time-offset", "0"});
  Child logger({SG_LCM_LOGGER, "--lcm-url=" + test_url(7914), "-c", "OBJECT_POSITION", log});
  ASSERT_TRUE(eventually(
      [&] { return listening_on_bus(live.pid(), 7914) && listening_on_bus(logger.pid(), 7914); },
      30s, "sg-predictor and lcm-logger to join the bus"));

  sim::ScenarioParams sp;
  sp.phase = 0.3;
  const auto motion = sim::make_scenario(sp);
  Bus a(test_url(7914));
  a.set_guard(vouching_as("sg-vision"));  // the predictor believes positions only from vision
  std::vector<Bytes> live_out, replay_out;
  listen(a, live_out);
  int k = 0;
  constexpr int kSamples = 160;
  collect(a, live_out, kSamples, 60s, [&] {
    if (k >= kSamples) return;
    stereograsp::point3_t p{};
    p.utime = 1'700'000'000'000'000 + static_cast<int64_t>(k) * 250'000;
    p.visible = !(k >= 100 && k < 110);  // a 2.5 s occlusion
    const Eigen::Vector3d x = motion->position(k * 0.25);
    for (int i = 0; i < 3; ++i) p.position[i] = p.visible ? x[i] : std::nan("");
    a.publish("OBJECT_POSITION", p);
    ++k;
    // Paced, so neither the live stream nor its replay at recorded speed is a burst that a
    // loaded machine's socket buffers could drop.
    std::this_thread::sleep_for(10ms);
  });
  logger.signal(SIGINT);
  live.signal(SIGINT);
  ASSERT_FALSE(logger.wait(10s).timed_out);
  const ProcessResult live_done = live.wait(10s);
  EXPECT_NE(live_done.out.find("published " + std::to_string(kSamples) +
                               " trajectories; 0 measurements rejected"),
            std::string::npos)
      << live_done.out << live_done.err;
  ASSERT_EQ(live_out.size(), static_cast<size_t>(kSamples));

  // An offline replay on a bus of its own, as scripts/replay.sh runs it: the log's counters are
  // old, so a guarded predictor would refuse them as stale (docs/security.md, "Replays").
  Child replayed({program("sg-predictor"), "--lcm-url", test_url(7915), "--max-time-offset", "0",
                  "--insecure-no-key"});
  ASSERT_TRUE(eventually([&] { return listening_on_bus(replayed.pid(), 7915); }, 30s,
                         "the replayed sg-predictor to join the bus"));
  Bus b(test_url(7915));
  listen(b, replay_out);
  Child player({SG_LCM_LOGPLAYER, "-s", "1", "-l", test_url(7915), log});  // at recorded speed
  collect(b, replay_out, kSamples, 60s);
  EXPECT_EQ(player.wait(30s).exit_code, 0);
  replayed.signal(SIGINT);
  replayed.wait(10s);
  ASSERT_EQ(replay_out.size(), live_out.size());
  for (size_t i = 0; i < live_out.size(); ++i)
    EXPECT_EQ(replay_out[i], live_out[i]) << "trajectory " << i;
  stereograsp::trajectory_t t;
  ASSERT_EQ(t.decode(live_out[105].data(), 0, static_cast<int>(live_out[105].size())),
            static_cast<int>(live_out[105].size()));
  EXPECT_EQ(t.status, stereograsp::trajectory_t::STATUS_OCCLUDED);
  EXPECT_EQ(t.occluded_samples, 6);
  EXPECT_EQ(t.num_points, 16);

  // Training from the same log, then starting from the coefficients.
  const ProcessResult trained =
      run({program("sg-predictor"), "train", log, "--out", dir + "/coeffs.yaml", "--order", "8"});
  ASSERT_EQ(trained.exit_code, 0) << trained.err;
  EXPECT_NE(trained.out.find("trained order 8 on 1"), std::string::npos) << trained.out;
  std::ifstream coeffs(dir + "/coeffs.yaml");
  std::stringstream text;
  text << coeffs.rdbuf();
  EXPECT_NE(text.str().find("order: 8"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("x: ["), std::string::npos) << text.str();
}

// Bad input: a coefficients file with the wrong count, an unknown model, a log that is not one.
TEST(Predictor, BadInputIsOneLine) {
  const std::string dir = make_temp_dir();
  std::ofstream(dir + "/short.yaml")
      << "order: 4\ncoefficients:\n  x: [1, 2]\n  y: [1, 2, 3, 4]\n  z: [1, 2, 3, 4]\n";
  std::ofstream(dir + "/notes.txt") << "not a log\n";
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"--coefficients", dir + "/short.yaml"},
           {"--model", "lstm"},
           {"train", dir + "/notes.txt", "--out", dir + "/c.yaml"},
           {"--order", "40", "--window", "20"}}) {
    std::vector<std::string> argv = {program("sg-predictor")};
    argv.insert(argv.end(), args.begin(), args.end());
    const ProcessResult r = run(argv, 20s);
    EXPECT_NE(r.exit_code, 0) << args[0];
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
  }
}

}  // namespace
}  // namespace sg::test
