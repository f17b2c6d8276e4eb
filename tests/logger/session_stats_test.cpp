// Session statistics on a synthetic 20-second log with known contents: rates, gaps, latency,
// camera modes, triangulation, prediction error against measurements and truth, an occlusion
// episode, the arm's interaction times and the grasp events.

#include "logger/session_stats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "common/message_types.hpp"
#include "logger/log_reader.hpp"
#include "logger/report.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::logger {
namespace {

using Vec3 = Eigen::Vector3d;

constexpr int64_t kT0 = 1'700'000'000'000'000;
constexpr double kOffset = 0.01;  // metres: every prediction is the circle plus this, in Z

/// The ball: a circle of radius 0.2 m around (0.5, 0, 0.2), one radian a second.
Vec3 circle(int64_t utime) {
  const double t = (utime - kT0) * 1e-6;
  return Vec3(0.5 + 0.2 * std::cos(t), 0.2 * std::sin(t), 0.2);
}

int64_t frame_utime(int k) { return kT0 + (static_cast<int64_t>(k) * 1'000'000 + 15) / 30; }

bool occluded(int k) { return k >= 300 && k < 345; }  // 10.0 s to 11.5 s

/// Writes messages in receive order with their receive times.
class Session {
 public:
  struct Item {
    int64_t recv;
    std::string channel;
    std::vector<uint8_t> bytes;
  };
  template <class T>
  void add(int64_t recv, const std::string& channel, const T& m) {
    items.push_back({recv, channel, encode_message(m)});
  }
  void write(const std::string& path) {
    std::stable_sort(items.begin(), items.end(),
                     [](const Item& a, const Item& b) { return a.recv < b.recv; });
    lcm::LogFile log(path, "w");
    for (Item& i : items) {
      lcm::LogEvent e;
      e.eventnum = 0;
      e.timestamp = i.recv;
      e.channel = i.channel;
      e.datalen = static_cast<int32_t>(i.bytes.size());
      e.data = i.bytes.data();
      log.writeEvent(&e);
    }
  }
  std::vector<Item> items;
};

std::string make_log() {
  Session s;
  for (int k = 0; k < 600; ++k) {  // 30 Hz for 20 s
    const int64_t u = frame_utime(k);
    stereograsp::point3_t p{};
    p.utime = u;
    p.visible = !occluded(k);
    const Vec3 x = circle(u);
    for (int i = 0; i < 3; ++i) p.position[i] = p.visible ? x[i] : NAN;
    p.reprojection_error = p.visible ? 0.5 : NAN;
    s.add(u + 5000, "OBJECT_POSITION", p);
    stereograsp::point3_t g{};
    g.utime = u;
    g.visible = true;
    for (int i = 0; i < 3; ++i) g.position[i] = x[i];
    g.reprojection_error = NAN;
    s.add(u + 2000, "GROUND_TRUTH", g);
    stereograsp::blob_t left{};
    left.utime = u;
    left.camera = stereograsp::blob_t::LEFT;
    left.found = !occluded(k);
    left.mode = (k >= 300 && k < 360) ? stereograsp::blob_t::MODE_FULL_FRAME
                                      : stereograsp::blob_t::MODE_TRACKING;
    s.add(u + 3000, "BLOB_LEFT", left);
    stereograsp::blob_t right = left;
    right.camera = stereograsp::blob_t::RIGHT;
    right.found = true;
    right.mode = stereograsp::blob_t::MODE_TRACKING;
    s.add(u + 3000, "BLOB_RIGHT", right);
  }
  for (int j = 0; j < 80; ++j) {  // 4 Hz
    stereograsp::trajectory_t t{};
    t.utime = kT0 + j * 250'000;
    t.source_utime = t.utime;
    t.period_us = 250'000;
    t.start_utime = t.utime + t.period_us;
    t.num_points = 16;
    for (int i = 0; i < 16; ++i) {
      const Vec3 x = circle(t.start_utime + i * t.period_us) + Vec3(0, 0, kOffset);
      t.position.push_back({x[0], x[1], x[2]});
      t.position_sigma.push_back({0.001, 0.001, 0.001});
    }
    const bool in_occlusion = t.utime >= kT0 + 10'000'000 && t.utime < kT0 + 11'500'000;
    t.status = in_occlusion ? stereograsp::trajectory_t::STATUS_OCCLUDED
                            : stereograsp::trajectory_t::STATUS_TRACKING;
    s.add(t.utime + 8000, "OBJECT_TRAJECTORY", t);
  }
  const double interactions[] = {0.72, 0.76, 0.80, 0.84, 0.78};
  for (int k = 0; k < 400; ++k) {  // 20 Hz
    stereograsp::arm_status_t a{};
    a.utime = kT0 + k * 50'000;
    const int change = k < 20 ? -1 : (k - 20) / 40;  // a new value every 2 s from 1 s on
    a.interaction_time = change < 0 ? 0 : interactions[change % 5];
    a.last_rejected_sequence = k >= 100 ? 7 : -1;  // one rejection
    a.tool_position[0] = 0.3;
    s.add(a.utime + 1000, "ARM_STATUS", a);
  }
  for (int k = 0; k < 20; ++k) {  // 1 Hz
    stereograsp::arm_cmd_t c{};
    c.utime = kT0 + k * 1'000'000 + 100'000;
    c.source_utime = c.utime - 50'000;
    c.mode = stereograsp::arm_cmd_t::MODE_CARTESIAN;
    c.position[0] = 0.4;
    c.speed = 0.5;
    s.add(c.utime + 10'000, "ARM_COMMAND", c);
  }
  for (int k = 0; k < 80; ++k) {      // 4 Hz: q0, q1 at 5 s, q2 at 8 s, q3 at 9 s, q4 + success at
    stereograsp::grasp_status_t g{};  // 10 s, back to q0 at 15 s
    g.utime = kT0 + k * 250'000;
    const double t = k * 0.25;
    g.state = t < 5 ? 0 : t < 8 ? 1 : t < 9 ? 2 : t < 10 ? 3 : t < 15 ? 4 : 0;
    g.outcome = t < 10 ? 0 : 1;
    g.last_action = -1;
    g.message = t >= 10 && t < 15 ? "held" : "";
    for (double& v : g.target) v = NAN;
    s.add(g.utime + 4000, "GRASP_STATUS", g);
  }
  for (int k = 0; k < 1000; ++k) {  // 50 Hz with 0.5 s missing after 5 s
    const int64_t u = kT0 + k * 20'000;
    if (u > kT0 + 5'000'000 && u < kT0 + 5'500'000) continue;
    stereograsp::sim_arm_state_t m{};
    m.utime = u;
    s.add(u + 500, "SIM_ARM_STATE", m);
  }
  const std::string path = test::make_temp_dir() + "/synthetic.lcmlog";
  s.write(path);
  return path;
}

class SessionStatsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    LogReader reader(make_log());
    stats_ = new SessionStats();
    LogRecord e;
    while (reader.next(e)) stats_->add(e);
    stats_->finish(reader);
  }
  static void TearDownTestSuite() { delete stats_; }
  static const SessionSummary& s() { return stats_->summary(); }
  static const ChannelSummary& channel(const std::string& name) {
    for (const ChannelSummary& c : s().channels)
      if (c.name == name) return c;
    throw std::runtime_error("no channel " + name);
  }
  static const LatencySummary& latency(const std::string& stage) {
    for (const LatencySummary& l : s().latency)
      if (l.stage == stage) return l;
    throw std::runtime_error("no stage " + stage);
  }
  static SessionStats* stats_;
};
SessionStats* SessionStatsTest::stats_ = nullptr;

// Counts, rates and types per channel; nothing wrong in the log.
TEST_F(SessionStatsTest, ChannelCountsAndRates) {
  EXPECT_EQ(s().channels.size(), 9u);
  EXPECT_TRUE(s().problems.empty());
  EXPECT_TRUE(s().unknown.empty());
  EXPECT_EQ(channel("OBJECT_POSITION").count, 600);
  EXPECT_EQ(channel("OBJECT_POSITION").type, "point3_t");
  EXPECT_EQ(channel("OBJECT_POSITION").decoded, 600);
  EXPECT_NEAR(channel("OBJECT_POSITION").rate_hz, 30.0, 1e-3);
  EXPECT_NEAR(channel("OBJECT_TRAJECTORY").rate_hz, 4.0, 1e-9);
  EXPECT_NEAR(channel("ARM_STATUS").rate_hz, 20.0, 1e-9);
  EXPECT_EQ(channel("GRASP_STATUS").type, "grasp_status_t");
}

// Gaps: the median period, and SIM_ARM_STATE's one missing half second.
TEST_F(SessionStatsTest, GapsAgainstTheMedianPeriod) {
  const ChannelSummary& pos = channel("OBJECT_POSITION");
  EXPECT_NEAR(pos.median_period_s, 1.0 / 30, 1e-5);
  EXPECT_EQ(pos.gaps_over_3x, 0);
  const ChannelSummary& sim = channel("SIM_ARM_STATE");
  EXPECT_NEAR(sim.median_period_s, 0.02, 1e-9);
  EXPECT_NEAR(sim.largest_gap_s, 0.5, 1e-9);
  EXPECT_NEAR(sim.largest_gap_at_s, 5.5, 1e-3);
  EXPECT_EQ(sim.gaps_over_3x, 1);
}

// Latency per stage: receive minus utime (or source_utime) as written.
TEST_F(SessionStatsTest, LatencyPerStage) {
  const LatencySummary& pos = latency("OBJECT_POSITION");
  EXPECT_EQ(pos.reference, "utime");
  EXPECT_EQ(pos.ms.count, 600);
  EXPECT_NEAR(pos.ms.p50, 5.0, 1e-9);
  EXPECT_NEAR(pos.ms.p99, 5.0, 1e-9);
  EXPECT_NEAR(latency("GROUND_TRUTH").ms.p95, 2.0, 1e-9);
  EXPECT_EQ(latency("OBJECT_TRAJECTORY").reference, "source_utime");
  EXPECT_NEAR(latency("OBJECT_TRAJECTORY").ms.p50, 8.0, 1e-9);
  EXPECT_NEAR(latency("ARM_COMMAND").ms.p50, 60.0, 1e-9);
  for (const LatencySummary& l : s().latency)  // source_utime 0: nothing to measure
    EXPECT_NE(l.stage, "GRASP_STATUS");
}

// Detection rate and time in search-window versus full-frame mode per camera.
TEST_F(SessionStatsTest, CameraDetectionAndModes) {
  ASSERT_EQ(s().cameras.size(), 2u);
  const CameraSummary& left = s().cameras[0];
  EXPECT_EQ(left.channel, "BLOB_LEFT");
  EXPECT_EQ(left.frames, 600);
  EXPECT_EQ(left.detected, 555);
  EXPECT_NEAR(left.detection_rate, 555.0 / 600, 1e-12);
  EXPECT_EQ(left.tracking_frames, 540);
  EXPECT_EQ(left.full_frame_frames, 60);
  EXPECT_NEAR(left.full_frame_s, 2.0, 1e-5);
  EXPECT_NEAR(left.tracking_s, (300 + 239) / 30.0, 1e-5);  // the last frame has no span
  EXPECT_NEAR(s().cameras[1].detection_rate, 1.0, 1e-12);
}

// Triangulation residuals of the visible positions.
TEST_F(SessionStatsTest, TriangulationResiduals) {
  EXPECT_EQ(s().triangulation.positions, 600);
  EXPECT_EQ(s().triangulation.visible, 555);
  EXPECT_NEAR(s().triangulation.residual_px.p95, 0.5, 1e-12);
  EXPECT_NEAR(s().triangulation.residual_px.mean, 0.5, 1e-12);
}

// Predictions are the circle plus a constant offset: the error is that offset at every h,
// against the truth and against the (interpolated) measurements.
TEST_F(SessionStatsTest, PredictionErrorEqualsTheOffset) {
  ASSERT_EQ(s().prediction.size(), 3u);
  for (const HorizonSummary& h : s().prediction) {
    SCOPED_TRACE("h = " + std::to_string(h.h));
    EXPECT_EQ(h.predictions, 80);
    EXPECT_GT(h.vs_truth.count, 50);
    EXPECT_NEAR(h.vs_truth.rms, kOffset, 1e-6);
    EXPECT_NEAR(h.vs_truth.p95, kOffset, 1e-6);
    EXPECT_NEAR(h.vs_truth.max, kOffset, 1e-6);
    EXPECT_GT(h.vs_measurement.count, 40);
    EXPECT_NEAR(h.vs_measurement.rms, kOffset, 1e-6);
    EXPECT_NEAR(h.vs_measurement.p95, kOffset, 1e-6);
    // Targets inside the occlusion have no bracketing measurements; those past the end of the
    // log have nothing at all.
    EXPECT_EQ(h.vs_measurement.count + h.unmatched_measurement, 80);
    EXPECT_EQ(h.vs_truth.count + h.unmatched_truth, 80);
    EXPECT_GT(h.vs_truth.count, h.vs_measurement.count);
  }
  EXPECT_EQ(s().prediction[0].h, 1);
  EXPECT_EQ(s().prediction[2].h, 16);
  EXPECT_EQ(s().prediction[2].vs_truth.count, 64);  // targets up to the last truth, 19.97 s
  EXPECT_FALSE(stats_->plot_data().predicted.points().empty());
}

// One occlusion of 1.5 s, its occluded trajectories, and the error across it.
TEST_F(SessionStatsTest, OcclusionEpisode) {
  EXPECT_EQ(s().occlusions.count, 1);
  ASSERT_EQ(s().occlusions.episodes.size(), 1u);
  const OcclusionEpisode& e = s().occlusions.episodes[0];
  EXPECT_NEAR(e.start_s, 10.0, 1e-3);  // session time starts at the first event, +0.5 ms
  EXPECT_NEAR(e.duration_s, 1.5, 1e-6);
  EXPECT_FALSE(e.gap);
  EXPECT_EQ(e.occluded_trajectories, 6);
  EXPECT_EQ(e.vs_truth.count, 18);  // targets in [10, 11.5): 6 per horizon
  EXPECT_NEAR(e.vs_truth.rms, kOffset, 1e-6);
  EXPECT_GT(e.after_vs_measurement.count, 0);
  EXPECT_NEAR(e.after_vs_measurement.max, kOffset, 1e-6);
  ASSERT_EQ(stats_->plot_data().occlusions.size(), 1u);
  EXPECT_NEAR(stats_->plot_data().occlusions[0].second, 11.5, 1e-3);
}

// Interaction times: one sample per change, within the 1.2 % resolution.
TEST_F(SessionStatsTest, ArmInteractionTimes) {
  const Quantiles& q = s().arm.interaction_s;
  EXPECT_EQ(q.count, 10);
  EXPECT_NEAR(q.mean, 0.78, 1e-12);
  EXPECT_NEAR(q.max, 0.84, 1e-12);
  EXPECT_NEAR(q.p50, 0.78, 1e-12);  // one distinct value in its bin: exact
  EXPECT_NEAR(q.p95, 0.84, 1e-12);
  EXPECT_EQ(s().arm.statuses, 400);
  EXPECT_EQ(s().arm.commands, 20);
  EXPECT_EQ(s().arm.rejections, 1);
  EXPECT_EQ(s().arm.command_modes.at("cartesian"), 20);
}

// Grasp events: every change of state or outcome, in order, and the outcome.
TEST_F(SessionStatsTest, GraspEvents) {
  const GraspSummary& g = s().grasp;
  ASSERT_EQ(g.events.size(), 6u);
  const std::vector<std::string> states = {"q0 hand opened", "q1 approaching",   "q2 grasping",
                                           "q3 hand closed", "q4 object lifted", "q0 hand opened"};
  const std::vector<double> times = {0, 5, 8, 9, 10, 15};
  for (size_t i = 0; i < states.size(); ++i) {
    EXPECT_EQ(g.events[i].state, states[i]) << i;
    EXPECT_NEAR(g.events[i].t_s, times[i], 1e-3) << i;
  }
  EXPECT_EQ(g.events[4].outcome, "success");
  EXPECT_EQ(g.events[4].message, "held");
  EXPECT_EQ(g.success, 1);
  EXPECT_EQ(g.failed, 0);
  EXPECT_EQ(stats_->plot_data().events.size(), 6u);
}

// PROCESS_STATUS: each process listed, a host whose clock is 800 ms off sg-grasp's is a problem,
// a process that stopped beating is reported at the time it fell silent, a clean stop is not.
TEST(SessionStatsProcesses, ClocksAndSilencesFromTheHeartbeats) {
  using stereograsp::process_status_t;
  SessionStats stats;
  auto beat = [&](const std::string& process, const std::string& host, int32_t pid, int64_t recv,
                  int8_t state = process_status_t::STATE_READY) {
    process_status_t s{};
    s.utime = recv;
    s.process = process;
    s.host = host;
    s.pid = pid;
    s.state = state;
    if (process == "sg-grasp") {  // it measured lab1's clock 800 ms behind its own
      s.num_peers = 1;
      s.peer = {"sg-vision@lab1:7"};
      s.peer_utime = s.peer_recv_utime = {0};
      s.peer_offset_us = {-800'000};
      s.peer_offset_error_us = {300};
    }
    const std::vector<uint8_t> bytes = encode_message(s);
    stats.add("PROCESS_STATUS", recv, bytes.data(), static_cast<int>(bytes.size()));
  };
  const int64_t t0 = 1'700'000'000'000'000;
  for (int k = 0; k <= 10; ++k) {
    const int64_t t = t0 + k * 1'000'000;
    beat("sg-grasp", "lab2", 9, t);
    if (k <= 4) beat("sg-vision", "lab1", 7, t + 1000);  // silent after 4 s
    if (k <= 6)
      beat("sg-predictor", "lab2", 8, t + 2000,
           k == 6 ? process_status_t::STATE_STOPPING : process_status_t::STATE_READY);
  }
  stats.finish();
  const ProcessesSummary& p = stats.summary().processes;
  ASSERT_EQ(p.processes.size(), 3u);
  EXPECT_EQ(p.processes[1].name, "sg-vision@lab1:7");
  EXPECT_NEAR(p.processes[1].last_s, 4.0, 1e-2);
  EXPECT_EQ(p.processes[2].last_state, "stopping");
  EXPECT_EQ(p.clock_reference, "lab2");
  ASSERT_EQ(p.clock_warnings.size(), 1u);
  EXPECT_NE(p.clock_warnings[0].find("clock of host lab1 is -800.0 ms off lab2's"),
            std::string::npos)
      << p.clock_warnings[0];
  ASSERT_EQ(p.events.size(), 2u);
  EXPECT_EQ(p.events[0], "6.0 s: sg-predictor@lab2:8 stopped");
  EXPECT_NE(p.events[1].find("sg-vision@lab1:7 stopped beating"), std::string::npos) << p.events[1];
  // Its last beat at 4.0 s; reported 2.5 s later at the log's next event after a check.
  EXPECT_GE(std::stod(p.events[1]), 6.5);
  EXPECT_LE(std::stod(p.events[1]), 7.0);
  const std::string md = report_markdown(stats.summary(), {});
  EXPECT_NE(md.find("- clock of host lab1"), std::string::npos);
  EXPECT_NE(md.find("## Processes"), std::string::npos);
}

// A histogram's percentiles: the bin's upper edge, within 12.2 % at 20 bins a decade.
TEST(LogHistogram, PercentilesWithinTheBinResolution) {
  LogHistogram h(1e-2, 1e5, 20);
  for (int i = 1; i <= 1000; ++i) h.add(i * 0.1);  // 0.1 .. 100
  EXPECT_EQ(h.count(), 1000);
  EXPECT_NEAR(h.mean(), 50.05, 1e-9);
  EXPECT_GE(h.percentile(0.5), 50.0);
  EXPECT_LE(h.percentile(0.5), 50.0 * h.bin_ratio());
  EXPECT_GE(h.percentile(0.95), 95.0);
  EXPECT_LE(h.percentile(0.95), 95.0 * h.bin_ratio());
  EXPECT_DOUBLE_EQ(h.percentile(1.0), 100.0);
  h.add(-3);  // below the range: underflow, still counted
  EXPECT_EQ(h.count(), 1001);
  EXPECT_DOUBLE_EQ(h.min(), -3);
}

// A message of another stereograsp type on a known channel is "wrong type", and is not used.
TEST(SessionStats, WrongTypeOnAKnownChannel) {
  SessionStats stats;
  stereograsp::blob_t b{};
  const std::vector<uint8_t> bytes = encode_message(b);
  stats.add("OBJECT_POSITION", kT0, bytes.data(), static_cast<int>(bytes.size()), 0);
  stats.finish();
  ASSERT_EQ(stats.summary().channels.size(), 1u);
  EXPECT_EQ(stats.summary().channels[0].wrong_type, 1);
  EXPECT_EQ(stats.summary().wrong_type, 1);
  EXPECT_EQ(stats.summary().triangulation.positions, 0);
}

// Each visible position is matched with the GROUND_TRUTH of its capture time, whichever comes
// first: 100 positions 1 mm from the truth and 100 positions 4 mm from it give p50 near 1 mm
// (the histogram's bin: within 12%), max 4 mm, RMS sqrt((1 + 16) / 2) mm; a position of no
// frame the truth has and an invisible one are not counted.
TEST(SessionStats, PositionsAgainstTheTruthOfTheirFrame) {
  SessionStats stats;
  auto add = [&](const std::string& channel, int64_t utime, const Vec3& x, bool visible) {
    stereograsp::point3_t p{};
    p.utime = utime;
    p.visible = visible;
    for (int i = 0; i < 3; ++i) p.position[i] = x[i];
    const std::vector<uint8_t> bytes = encode_message(p);
    stats.add(channel, utime + 1000, bytes.data(), static_cast<int>(bytes.size()), 0);
  };
  for (int k = 0; k < 200; ++k) {
    const int64_t u = kT0 + k * 33'333;
    const Vec3 truth = circle(u), seen = truth + Vec3(0, k < 100 ? 0.001 : 0.004, 0);
    if (k % 2 == 0) add("GROUND_TRUTH", u, truth, true), add("OBJECT_POSITION", u, seen, true);
    if (k % 2 == 1) add("OBJECT_POSITION", u, seen, true), add("GROUND_TRUTH", u, truth, true);
  }
  add("OBJECT_POSITION", kT0 + 7, circle(kT0), true);  // no truth at this time
  add("OBJECT_POSITION", kT0 + 33'333 * 201, Vec3::Zero(), false);
  add("GROUND_TRUTH", kT0 + 33'333 * 201, Vec3::Ones(), true);
  stats.finish();
  const Quantiles& e = stats.summary().triangulation.vs_truth_m;
  EXPECT_EQ(e.count, 200);
  EXPECT_NEAR(e.p50, 0.001, 0.00012);
  EXPECT_NEAR(e.max, 0.004, 1e-12);
  EXPECT_NEAR(e.rms, std::sqrt((1e-6 + 16e-6) / 2), 1e-9);
}

}  // namespace
}  // namespace sg::logger
