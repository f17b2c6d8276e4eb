// Every datum vouched for, with real processes over real LCM and a real pseudo-terminal: the
// closed loop tracks the simulated ball while two intruders on the bus forge what the commander
// obeys, at 20 Hz each, 150 mm to the side of the real ball — one a host without credentials
// (OBJECT_TRAJECTORY, OBJECT_POSITION, BLOB_*, ARM_STATUS, and CAMERA_* images recorded a few
// seconds earlier), one a host that holds only the cameras' credentials (OBJECT_TRAJECTORY,
// OBJECT_POSITION, ARM_STATUS, BLOB_*, all vouched for as sg-camera-sim). The arm keeps following
// the real ball, each refusal is counted on sg-grasp's and sg-predictor's PROCESS_STATUS, and the
// grasp that follows, under the same attack, holds the ball. Then the same forgery against
// processes started with --insecure-no-key: the arm goes to the made-up ball (the check is what
// holds it).

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/paper_circle.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;

constexpr double kSide = 0.15;  // m: where the forgeries put the ball, beside the real one

/// What the test watches: the true ball and tool (the simulators' own channels, which nobody
/// forges here), sg-grasp's state, and the PROCESS_STATUS of every process.
struct Truth {
  explicit Truth(Bus& bus) {
    bus.subscribe<stereograsp::point3_t>("GROUND_TRUTH",
                                         [this](const auto& m, const auto&) { ball = m; });
    bus.subscribe<stereograsp::sim_arm_state_t>("SIM_ARM_STATE",
                                                [this](const auto& m, const auto&) {
                                                  arm = m;
                                                  ++arm_states;
                                                });
    bus.subscribe<stereograsp::grasp_status_t>("GRASP_STATUS",
                                               [this](const auto& m, const auto&) { grasp = m; });
    bus.subscribe<stereograsp::process_status_t>(
        "PROCESS_STATUS", [this](const auto& m, const auto&) { status[m.process] = m; });
  }
  /// The tool's horizontal distance from the true ball (the stand-off is vertical).
  double tool_to_ball() const {
    return std::hypot(arm.tool_position[0] - ball.position[0],
                      arm.tool_position[1] - ball.position[1]);
  }
  /// ... and from the made-up ball kSide to its side.
  double tool_to_forgery() const {
    return std::hypot(arm.tool_position[0] - ball.position[0],
                      arm.tool_position[1] - ball.position[1] - kSide);
  }
  bool tracking() const { return grasp.activity == stereograsp::grasp_status_t::ACTIVITY_TRACKING; }
  stereograsp::point3_t ball{};
  stereograsp::sim_arm_state_t arm{};
  int arm_states = 0;
  stereograsp::grasp_status_t grasp{};
  std::map<std::string, stereograsp::process_status_t> status;
};

/// A forecast as sg-predictor would publish it at `now`, of a ball kSide beside the real one
/// (`real`, GROUND_TRUTH), still, sure of itself: a ball that is not there.
stereograsp::trajectory_t forged_forecast(int64_t now, const stereograsp::point3_t& real) {
  stereograsp::trajectory_t m{};
  m.utime = now - 50'000;
  m.source_utime = m.utime;
  m.period_us = 250'000;
  m.start_utime = now + m.period_us;
  m.num_points = 16;
  m.position.assign(16, {real.position[0], real.position[1] + kSide, real.position[2]});
  m.position_sigma.assign(16, {0.0005, 0.0005, 0.0005});
  m.status = stereograsp::trajectory_t::STATUS_TRACKING;
  return m;
}

/// An intruder: its own bus (vouching as `identity`, or with no credentials when ""), publishing
/// forgeries at 20 Hz from forge(): forecasts and positions kSide beside the real ball, and with
/// `all`, blobs and an ARM_STATUS of an idle arm that executed everything, and the camera frames
/// it heard 3 s earlier replayed as new ones (the ball where it was then).
class Intruder {
 public:
  Intruder(const std::string& url, const std::string& identity, bool all)
      : bus_(url), images_(all && identity.empty()), all_(all) {
    if (!identity.empty()) bus_.set_guard(vouching_as(identity));
    if (images_) {
      for (const char* c : {"CAMERA_LEFT", "CAMERA_RIGHT"}) {
        bus_.subscribe<stereograsp::image_t>(
            c,
            [this, c](const auto& m, const auto&) {
              heard_.push_back({c, m});
            },
            kQueueFrames);
      }
    }
  }
  /// Publishes one round of forgeries at most every 50 ms; reads the bus meanwhile.
  void forge(const stereograsp::point3_t& real_ball) {
    bus_.handle(0ms);
    const int64_t now = now_utime();
    if (now - last_ < 50'000) return;
    last_ = now;
    bus_.publish("OBJECT_TRAJECTORY", forged_forecast(now, real_ball));
    stereograsp::point3_t p = real_ball;
    p.utime = now - 50'000;
    p.position[1] += kSide;
    p.visible = 1;
    bus_.publish("OBJECT_POSITION", p);
    ++rounds_;
    if (!all_) return;
    stereograsp::arm_status_t s{};
    s.utime = now;
    s.state = stereograsp::arm_status_t::STATE_IDLE;
    s.last_executed_sequence = std::numeric_limits<int64_t>::max();
    bus_.publish("ARM_STATUS", s);
    for (int8_t c = 0; c < 2; ++c) {
      stereograsp::blob_t b{};
      b.utime = now;
      b.camera = c;
      b.found = 1;
      bus_.publish(c == 0 ? "BLOB_LEFT" : "BLOB_RIGHT", b);
    }
    while (images_ && !heard_.empty() && heard_.front().second.utime < now - 3'000'000) {
      auto [channel, image] = heard_.front();
      heard_.pop_front();
      image.utime = now - 20'000;  // an old frame passed off as new
      bus_.publish(channel, image);
      ++images_sent_;
    }
  }
  int rounds() const { return rounds_; }
  int images_sent() const { return images_sent_; }

 private:
  Bus bus_;
  bool images_, all_;
  std::deque<std::pair<std::string, stereograsp::image_t>> heard_;
  int64_t last_ = 0;
  int rounds_ = 0;
  int images_sent_ = 0;
};

/// The loop's processes, started with `extra` flags each (--insecure-no-key, or none).
struct Loop {
  Loop(const std::string& url, const std::string& dir, int port,
       const std::vector<std::string>& extra) {
    write_circle(dir + "/circle.csv");
    EXPECT_EQ(
        run({program("sg-predictor"), "train", dir + "/circle.csv", "--out", dir + "/coeffs.yaml"})
            .exit_code,
        0);
    EXPECT_EQ(run({program("sg-camera-sim"), "--snapshot", dir + "/pair.png", "--calibration-out",
                   dir + "/cams.yaml", "--log-level", "warn"})
                  .exit_code,
              0);
    const auto start = [&](std::vector<std::string> args) {
      args.insert(args.begin() + 1, {"--lcm-url", url, "--log-level", "warn"});
      args.insert(args.end(), extra.begin(), extra.end());
      children.push_back(std::make_unique<Child>(args));
    };
    start({program("sg-c550-sim"), "--link", dir + "/c550"});
    EXPECT_TRUE(eventually([&] { return std::filesystem::exists(dir + "/c550"); }, 30s,
                           "sg-c550-sim's pseudo-terminal"));
    start({program("sg-arm-driver"), "--device", dir + "/c550"});
    start({program("sg-vision"), "--calibration", dir + "/cams.yaml"});
    start({program("sg-predictor"), "--coefficients", dir + "/coeffs.yaml"});
    start({program("sg-grasp"), "--max-wait", "40"});
    EXPECT_TRUE(eventually(
        [&] {
          return std::all_of(children.begin(), children.end(),
                             [&](auto& c) { return joined_bus(c->pid(), port); });
        },
        60s, "the loop's processes to join the bus"));
    start({program("sg-camera-sim"), "--rate", "10"});
  }
  ~Loop() {
    for (auto& c : children) c->signal(SIGINT);
    for (auto& c : children) c->wait(10s);
  }
  std::vector<std::unique_ptr<Child>> children;
};

/// Runs the bus and both intruders for `seconds`, sampling the tool's distance to the real and
/// to the made-up ball every 50 ms while sg-grasp tracks; returns the medians.
std::pair<double, double> under_attack(Bus& bus, Truth& truth, std::vector<Intruder*> intruders,
                                       double seconds) {
  std::vector<double> to_ball, to_forgery;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  auto next_sample = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() < end) {
    bus.handle(5ms);
    for (Intruder* i : intruders) i->forge(truth.ball);
    if (std::chrono::steady_clock::now() >= next_sample && truth.tracking()) {
      next_sample += 50ms;
      to_ball.push_back(truth.tool_to_ball());
      to_forgery.push_back(truth.tool_to_forgery());
    }
  }
  const auto median = [](std::vector<double> v) {
    if (v.empty()) return std::nan("");
    std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  return {median(to_ball), median(to_forgery)};
}

/// Starts tracking and waits until the arm follows the real ball (horizontally within 3 cm).
::testing::AssertionResult start_tracking(Bus& bus, Truth& truth, const std::string& url,
                                          const std::vector<std::string>& extra) {
  if (auto r = eventually(
          bus, [&] { return truth.arm_states > 0 && truth.ball.utime > 0; }, 60s,
          "the simulated arm and ball");
      !r)
    return r;
  std::vector<std::string> track = {program("sg-grasp-ctl"), "--lcm-url", url, "track"};
  track.insert(track.end(), extra.begin(), extra.end());
  for (int attempt = 0; attempt < 5; ++attempt) {  // refused until sg-grasp has a forecast
    if (run(track, 20s).exit_code == 0) break;
    wait_until(
        bus, [] { return false; }, 2s);
  }
  return eventually(
      bus, [&] { return truth.tracking() && truth.tool_to_ball() < 0.03; }, 90s,
      "the arm to follow the real ball");
}

// The vouched loop: forgeries from a host without credentials and from one with the cameras'
// credentials, during tracking and during the grasp; the arm follows the real ball, the refusals
// are counted, and the grasp holds the ball.
TEST(ForgedData, TheArmFollowsOnlyWhatTheLabVouchedFor) {
  constexpr int kPort = 7931;
  ASSERT_TRUE(multicast_available(kPort));
  const std::string url = test_url(kPort), dir = make_temp_dir();
  Bus bus(url);
  Truth truth(bus);
  Loop loop(url, dir, kPort, {});
  ASSERT_TRUE(start_tracking(bus, truth, url, {}));
  const auto [before, before_forgery] = under_attack(bus, truth, {}, 10);

  Intruder stranger(url, "", true), cameras_host(url, "sg-camera-sim", true);
  const auto [during, during_forgery] = under_attack(bus, truth, {&stranger, &cameras_host}, 15);
  std::printf(
      "tool to the real ball (median, horizontal): %.1f mm before the forgery, %.1f mm "
      "during it; to the made-up ball %.1f mm during it\n",
      before * 1e3, during * 1e3, during_forgery * 1e3);
  EXPECT_GT(stranger.rounds(), 200);
  EXPECT_GT(stranger.images_sent(), 20);
  EXPECT_LT(during, 0.03) << "before the forgery " << before;
  EXPECT_LT(during, before + 0.01) << "before the forgery " << before;
  EXPECT_GT(during_forgery, 0.10);
  // Each forgery refused where it was aimed, counted by channel and verdict.
  const auto& grasp = truth.status["sg-grasp"];
  EXPECT_GT(unvouched(grasp, "OBJECT_TRAJECTORY", "unsigned"), 200);
  EXPECT_GT(unvouched(grasp, "OBJECT_TRAJECTORY", "not allowed"), 200);
  EXPECT_GT(unvouched(grasp, "ARM_STATUS", "unsigned"), 200);
  EXPECT_GT(unvouched(grasp, "ARM_STATUS", "not allowed"), 200);
  EXPECT_GT(unvouched(truth.status["sg-predictor"], "OBJECT_POSITION", "not allowed"), 200);
  EXPECT_GT(unvouched(truth.status["sg-vision"], "CAMERA_LEFT", "unsigned"), 10);

  // The grasp, with the forgeries going on: held.
  std::optional<ProcessResult> grasped;
  Child ctl({program("sg-grasp-ctl"), "--lcm-url", url, "grasp", "--wait", "--timeout", "90"});
  const auto deadline = std::chrono::steady_clock::now() + 100s;
  while (ctl.running() && std::chrono::steady_clock::now() < deadline) {
    bus.handle(5ms);
    stranger.forge(truth.ball);
    cameras_host.forge(truth.ball);
  }
  const ProcessResult r = ctl.wait(5s);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  wait_until(
      bus, [&] { return truth.arm.holding_object != 0; }, 10s);
  EXPECT_TRUE(truth.arm.holding_object) << "the simulated gripper does not hold the ball";
}

// The same forgery against the loop started with --insecure-no-key: nothing is checked, and the
// arm goes to the made-up ball. What the test above would see without the check.
TEST(ForgedData, WithoutVouchingTheArmFollowsTheForgery) {
  constexpr int kPort = 7932;
  ASSERT_TRUE(multicast_available(kPort));
  const std::string url = test_url(kPort), dir = make_temp_dir();
  const std::vector<std::string> insecure = {"--insecure-no-key"};
  Bus bus(url);
  Truth truth(bus);
  Loop loop(url, dir, kPort, insecure);
  ASSERT_TRUE(start_tracking(bus, truth, url, insecure));
  Intruder stranger(url, "", false);
  under_attack(bus, truth, {&stranger}, 5);  // the arm's way over
  const auto [during, during_forgery] = under_attack(bus, truth, {&stranger}, 10);
  std::printf("insecure: tool to the real ball %.1f mm, to the made-up ball %.1f mm (medians)\n",
              during * 1e3, during_forgery * 1e3);
  EXPECT_GT(during, 0.10);
  EXPECT_LT(during_forgery, 0.05);
}

}  // namespace
}  // namespace sg::test
