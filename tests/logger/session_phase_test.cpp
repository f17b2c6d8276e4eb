// The phases of a session (logger/session_phase.hpp): the rule from GRASP_STATUS alone and with
// SIM_ARM_STATE, the phase at an earlier time, the time in each; and the prediction error per
// phase (logger/session_stats.hpp) on a synthetic session whose predictions are off by a known
// amount in each phase, so each phase's RMS is that amount.

#include "logger/session_phase.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/message_types.hpp"
#include "logger/report.hpp"
#include "logger/session_stats.hpp"

namespace sg::logger {
namespace {

using Vec3 = Eigen::Vector3d;
using Status = stereograsp::grasp_status_t;

constexpr int64_t kT0 = 1'700'000'000'000'000;

int64_t at_s(double seconds) { return kT0 + static_cast<int64_t>(std::llround(seconds * 1e6)); }

// From GRASP_STATUS alone: the arm commanded before any grasp machine is the calibration; q0
// idle is idle; q0 tracking and q1 (waiting to close) are tracking; q2 is the approach; q3 and q4
// are the carried ball.
TEST(SessionPhase, FromTheGraspMachineAlone) {
  SessionPhase p;
  p.advance(at_s(0));
  EXPECT_EQ(p.current(), Phase::kNoGraspMachine);
  p.on_arm_command(at_s(1));
  EXPECT_EQ(p.current(), Phase::kCalibration);
  p.advance(at_s(9));  // no SIM_ARM_STATE to go stale: still the calibration
  EXPECT_EQ(p.current(), Phase::kCalibration);
  const struct {
    int state, activity;
    Phase phase;
  } steps[] = {{Status::Q0_HAND_OPENED, Status::ACTIVITY_IDLE, Phase::kIdle},
               {Status::Q0_HAND_OPENED, Status::ACTIVITY_TRACKING, Phase::kTracking},
               {Status::Q1_APPROACHING, Status::ACTIVITY_GRASPING, Phase::kTracking},
               {Status::Q2_GRASPING, Status::ACTIVITY_GRASPING, Phase::kApproach},
               {Status::Q3_HAND_CLOSED, Status::ACTIVITY_GRASPING, Phase::kCarried},
               {Status::Q4_OBJECT_LIFTED, Status::ACTIVITY_IDLE, Phase::kCarried},
               {Status::Q0_HAND_OPENED, Status::ACTIVITY_HOMING, Phase::kIdle},
               {Status::Q0_HAND_OPENED, Status::ACTIVITY_BACKING_OFF, Phase::kIdle}};
  double t = 10;
  for (const auto& step : steps) {
    p.on_grasp_status(at_s(t), step.state, step.activity);
    EXPECT_EQ(p.current(), step.phase) << t;
    t += 1;
  }
}

// Where SIM_ARM_STATE is fresh its holding_object decides whether the ball is held: held before
// the grasp machine is the calibration (no ARM_COMMAND needed), an empty hand in q3 is idle, a
// held ball in q0 is carried; a second after the last one the GRASP_STATUS rule holds again.
TEST(SessionPhase, SimArmStateWherePresent) {
  SessionPhase p;
  p.on_sim_arm_state(at_s(0), true);
  EXPECT_EQ(p.current(), Phase::kCalibration);
  p.on_sim_arm_state(at_s(1), false);
  p.on_arm_command(at_s(1.5));  // the simulator says the hand is empty: not a calibration
  EXPECT_EQ(p.current(), Phase::kNoGraspMachine);
  p.on_grasp_status(at_s(2), Status::Q3_HAND_CLOSED, Status::ACTIVITY_IDLE);
  EXPECT_EQ(p.current(), Phase::kIdle);  // closed on nothing
  p.on_grasp_status(at_s(2.5), Status::Q0_HAND_OPENED, Status::ACTIVITY_IDLE);
  p.on_sim_arm_state(at_s(2.6), true);
  EXPECT_EQ(p.current(), Phase::kCarried);
  p.on_sim_arm_state(at_s(3), false);
  p.on_grasp_status(at_s(3.2), Status::Q3_HAND_CLOSED, Status::ACTIVITY_IDLE);
  EXPECT_TRUE(p.advance(at_s(4.0) + 1));  // 1 s after the last SIM_ARM_STATE: stale
  EXPECT_EQ(p.current(), Phase::kCarried);
}

// The phase at an earlier time: a change at time t holds from t on; before the first event, the
// first phase; the seconds in each phase add up to the session's length.
TEST(SessionPhase, PhaseAtEarlierTimesAndTimeInEach) {
  SessionPhase p;
  p.advance(at_s(0));
  p.on_grasp_status(at_s(2), Status::Q0_HAND_OPENED, Status::ACTIVITY_TRACKING);
  p.on_grasp_status(at_s(5), Status::Q2_GRASPING, Status::ACTIVITY_GRASPING);
  p.on_grasp_status(at_s(6), Status::Q3_HAND_CLOSED, Status::ACTIVITY_GRASPING);
  p.advance(at_s(10));
  EXPECT_EQ(p.at(at_s(-1)), Phase::kNoGraspMachine);
  EXPECT_EQ(p.at(at_s(2) - 1), Phase::kNoGraspMachine);
  EXPECT_EQ(p.at(at_s(2)), Phase::kTracking);
  EXPECT_EQ(p.at(at_s(4.9)), Phase::kTracking);
  EXPECT_EQ(p.at(at_s(5.5)), Phase::kApproach);
  EXPECT_EQ(p.at(at_s(60)), Phase::kCarried);
  EXPECT_DOUBLE_EQ(p.seconds_in(Phase::kNoGraspMachine), 2);
  EXPECT_DOUBLE_EQ(p.seconds_in(Phase::kTracking), 3);
  EXPECT_DOUBLE_EQ(p.seconds_in(Phase::kApproach), 1);
  EXPECT_DOUBLE_EQ(p.seconds_in(Phase::kCarried), 4);
  EXPECT_DOUBLE_EQ(p.seconds_in(Phase::kIdle), 0);
}

// A log's receive times can be any int64: from the lowest to the highest the time in a phase is
// their difference, 2^64 us, not an overflowed int64.
TEST(SessionPhase, TimesAtTheInt64LimitsDoNotOverflow) {
  SessionPhase p;
  p.advance(std::numeric_limits<int64_t>::min());
  p.advance(std::numeric_limits<int64_t>::max());
  EXPECT_DOUBLE_EQ(p.seconds_in(Phase::kNoGraspMachine), 18446744073709.551616);
}

// Memory stays bounded: past kMaxChanges changes the oldest are forgotten, and a time before
// those kept has no phase; the recent ones are still known.
TEST(SessionPhase, KeepsTheLastChangesOnly) {
  SessionPhase p;
  const int n = static_cast<int>(SessionPhase::kMaxChanges) + 10;
  for (int i = 0; i < n; ++i) {
    const int state = i % 2 == 0 ? Status::Q2_GRASPING : Status::Q3_HAND_CLOSED;
    p.on_grasp_status(kT0 + i * 1000, state, Status::ACTIVITY_GRASPING);
  }
  EXPECT_FALSE(p.at(kT0).has_value());
  EXPECT_EQ(p.at(kT0 + (n - 1) * 1000), Phase::kCarried);
  EXPECT_EQ(p.at(kT0 + (n - 2) * 1000 + 500), Phase::kApproach);
}

// --- the prediction error per phase ---------------------------------------------------------

/// The ball: a circle of radius 0.2 m in the X-Y plane, one radian a second. Every error put in
/// below is along Z, so it is the whole error whatever the interpolation does in X-Y.
Vec3 circle(int64_t utime) {
  const double t = static_cast<double>(utime - kT0) * 1e-6;
  return Vec3(0.5 + 0.2 * std::cos(t), 0.2 * std::sin(t), 0.2);
}

/// The session's schedule on the log's clock, seconds: the arm commanded at 0 (the
/// calibration), GRASP_STATUS from 10.125 s: q0 idle, q0 tracking from 12.125 s, q1 from
/// 30.125 s, q2 from 32.125 s, q3 from 33.125 s, q4 from 34.125 s to the end (45 s).
Phase scheduled_phase(double s) {
  if (s < 10.125) return Phase::kCalibration;
  if (s < 12.125) return Phase::kIdle;
  if (s < 32.125) return Phase::kTracking;
  if (s < 33.125) return Phase::kApproach;
  return Phase::kCarried;
}
int scheduled_state(double s) {
  return s < 30.125   ? Status::Q0_HAND_OPENED
         : s < 32.125 ? Status::Q1_APPROACHING
         : s < 33.125 ? Status::Q2_GRASPING
         : s < 34.125 ? Status::Q3_HAND_CLOSED
                      : Status::Q4_OBJECT_LIFTED;
}
int scheduled_activity(double s) {
  return s < 12.125   ? Status::ACTIVITY_IDLE
         : s < 30.125 ? Status::ACTIVITY_TRACKING
                      : Status::ACTIVITY_GRASPING;
}

/// Trajectories j = 0..159 at j / 4 s, received 8 ms later; those of 20.0-20.75 s coast.
constexpr int kTrajectories = 160;
constexpr int64_t kTrajectoryLatency = 8000;
bool coasting(int j) { return j >= 80 && j < 84; }

/// The error put into a prediction made in phase `made` for a target in phase `then`, metres.
double error_put_in(Phase made, Phase then, bool coasts) {
  if (made != then) return 0.100;
  if (coasts) return 0.020;
  switch (made) {
    case Phase::kCalibration:
      return 0.040;
    case Phase::kIdle:
      return 0.005;
    case Phase::kTracking:
      return 0.001;
    case Phase::kApproach:
      return 0.003;
    default:
      return 0.060;
  }
}

template <class T>
void add(SessionStats& stats, const std::string& channel, int64_t recv, const T& message) {
  const std::vector<uint8_t> bytes = encode_message(message);
  stats.add(channel, recv, bytes.data(), static_cast<int>(bytes.size()), 0);
}

stereograsp::trajectory_t trajectory(int j) {
  stereograsp::trajectory_t m{};
  m.utime = kT0 + j * 250'000;
  m.source_utime = m.utime;
  m.period_us = 250'000;
  m.start_utime = m.utime + m.period_us;
  m.num_points = 16;
  m.status = coasting(j) ? m.STATUS_OCCLUDED : m.STATUS_TRACKING;
  m.occluded_samples = coasting(j) ? 1 : 0;
  m.model = m.MODEL_BURG;
  const double made_s = static_cast<double>(m.utime + kTrajectoryLatency - kT0) * 1e-6;
  for (int i = 0; i < 16; ++i) {
    const int64_t target = m.start_utime + i * m.period_us;
    const double target_s = made_s + static_cast<double>(target - m.utime) * 1e-6;
    const double e = error_put_in(scheduled_phase(made_s), scheduled_phase(target_s), coasting(j));
    const Vec3 x = circle(target) + Vec3(0, 0, e);
    m.position.push_back({x[0], x[1], x[2]});
    m.position_sigma.push_back({0.001, 0.001, 0.001});
  }
  return m;
}

/// The session, event by event in receive order: positions and truth every 25 ms (so every
/// target time is a sample: the reference is exact), GRASP_STATUS every 250 ms from 10.125 s,
/// trajectories every 250 ms, one ARM_COMMAND first.
void feed(SessionStats& stats) {
  stereograsp::arm_cmd_t c{};
  c.utime = kT0;
  c.mode = c.MODE_CARTESIAN;
  add(stats, "ARM_COMMAND", kT0, c);
  for (int64_t u = kT0; u <= at_s(45); u += 25'000) {
    const int64_t since = u - kT0;
    if (since % 250'000 == 125'000 && u >= at_s(10.125)) {
      const double s = static_cast<double>(since) * 1e-6;
      stereograsp::grasp_status_t g{};
      g.utime = u;
      g.state = static_cast<int8_t>(scheduled_state(s));
      g.activity = static_cast<int8_t>(scheduled_activity(s));
      for (double& v : g.target) v = NAN;
      add(stats, "GRASP_STATUS", u, g);
    }
    stereograsp::point3_t p{};
    p.utime = u;
    p.visible = true;
    const Vec3 x = circle(u);
    for (int i = 0; i < 3; ++i) p.position[i] = x[i];
    add(stats, "GROUND_TRUTH", u + 1000, p);
    add(stats, "OBJECT_POSITION", u + 2000, p);
    const int j = static_cast<int>(since / 250'000);
    if (since % 250'000 == 0 && j < kTrajectories)
      add(stats, "OBJECT_TRAJECTORY", u + kTrajectoryLatency, trajectory(j));
  }
  stats.finish();
}

const PhasePrediction& row(const SessionSummary& s, const std::string& key) {
  for (const PhasePrediction& p : s.prediction_by_phase)
    if (p.key == key) return p;
  throw std::runtime_error("no phase " + key);
}

/// How many predictions at horizon h the schedule puts in each row (the phases' keys, then
/// "coasting" and "across_phases"), counting only targets that the log's samples reach.
std::map<std::string, int64_t> scheduled_counts(int h) {
  std::map<std::string, int64_t> n;
  for (int j = 0; j < kTrajectories; ++j) {
    const double made = j * 0.25 + kTrajectoryLatency * 1e-6, target = made + h * 0.25;
    if (target > 45) continue;
    const Phase a = scheduled_phase(made), b = scheduled_phase(target);
    const bool held = a == Phase::kCalibration || a == Phase::kCarried;
    ++n[a != b ? "across_phases" : coasting(j) && !held ? "coasting" : phase_key(a)];
  }
  return n;
}

class PhaseErrorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    stats_ = new SessionStats();
    feed(*stats_);
  }
  static void TearDownTestSuite() { delete stats_; }
  static const SessionSummary& s() { return stats_->summary(); }
  static SessionStats* stats_;
};
SessionStats* PhaseErrorTest::stats_ = nullptr;

// Each phase's RMS, p95 and max are the error put into it alone, against the measurements and
// the truth alike, at every horizon: 1 mm while tracking, 3 mm in the approach, 5 mm idle, 40 mm
// in the calibration, 60 mm carried, 20 mm coasting, 100 mm for predictions across two phases.
TEST_F(PhaseErrorTest, EachPhaseHasItsOwnError) {
  const std::map<std::string, double> put_in = {
      {"calibration", 0.040}, {"idle", 0.005},     {"tracking", 0.001},     {"approach", 0.003},
      {"carried", 0.060},     {"coasting", 0.020}, {"across_phases", 0.100}};
  ASSERT_EQ(s().prediction_by_phase.size(), 8u);
  for (const auto& [key, e] : put_in) {
    for (const PhaseHorizon& h : row(s(), key).horizons) {
      SCOPED_TRACE(key + ", h = " + std::to_string(h.h));
      for (const Quantiles* q : {&h.vs_measurement, &h.vs_truth}) {
        if (h.h == 1) {
          ASSERT_GT(q->count, 0);  // the approach's 1 s has no room for h = 4 or 16
        }
        if (q->count == 0) continue;
        EXPECT_NEAR(q->rms, e, 1e-9);
        EXPECT_NEAR(q->max, e, 1e-9);
        EXPECT_NEAR(q->p95, e, 1e-9);
      }
    }
  }
  for (const PhaseHorizon& h : row(s(), "no_grasp_machine").horizons)
    EXPECT_EQ(h.vs_truth.count, 0);
}

// The counts follow the schedule: tracking holds the trajectories made from 12.25 s to 32.0 s
// (80) but the 4 that coast, less those whose target lies past 32.125 s (the approach): 75 at
// h = 1, 72 at h = 4, 60 at h = 16; every scored prediction is in exactly one row.
TEST_F(PhaseErrorTest, CountsFollowTheSchedule) {
  for (size_t hi = 0; hi < 3; ++hi) {
    const int h = s().prediction[hi].h;
    SCOPED_TRACE("h = " + std::to_string(h));
    const std::map<std::string, int64_t> expected = scheduled_counts(h);
    int64_t total = 0;
    for (const PhasePrediction& p : s().prediction_by_phase) {
      const auto it = expected.find(p.key);
      EXPECT_EQ(p.horizons[hi].vs_truth.count, it == expected.end() ? 0 : it->second) << p.key;
      EXPECT_EQ(p.horizons[hi].vs_measurement.count, p.horizons[hi].vs_truth.count) << p.key;
      total += p.horizons[hi].vs_truth.count;
    }
    EXPECT_EQ(total, s().prediction[hi].vs_truth.count);
  }
  EXPECT_EQ(row(s(), "tracking").horizons[0].vs_truth.count, 75);
  EXPECT_EQ(row(s(), "tracking").horizons[1].vs_truth.count, 72);
  EXPECT_EQ(row(s(), "tracking").horizons[2].vs_truth.count, 60);
  EXPECT_EQ(row(s(), "coasting").horizons[2].vs_truth.count, 4);
}

// The overall figures still hold every prediction; the time in each phase is the schedule's.
TEST_F(PhaseErrorTest, OverallFiguresAndTimeInEachPhase) {
  EXPECT_EQ(s().prediction[0].predictions, kTrajectories);
  EXPECT_GT(s().prediction[0].vs_truth.rms, 0.001);
  EXPECT_NEAR(row(s(), "calibration").duration_s, 10.125, 1e-9);
  EXPECT_NEAR(row(s(), "idle").duration_s, 2, 1e-9);
  EXPECT_NEAR(row(s(), "tracking").duration_s, 20, 1e-9);
  EXPECT_NEAR(row(s(), "approach").duration_s, 1, 1e-9);
  EXPECT_NEAR(row(s(), "carried").duration_s, 45.002 - 33.125, 1e-9);  // the last event: 45.002 s
  EXPECT_NEAR(row(s(), "no_grasp_machine").duration_s, 0, 1e-9);
  EXPECT_TRUE(std::isnan(row(s(), "coasting").duration_s));
}

// report.json names each phase by its key with the errors in metres (the overall "prediction"
// stays); report.md has a row per phase and horizon in millimetres, none for a phase never
// entered; the console summary gives the tracking phase.
TEST_F(PhaseErrorTest, InTheReports) {
  const nlohmann::json j = nlohmann::json::parse(report_json(s()));
  ASSERT_TRUE(j.contains("prediction"));
  const nlohmann::json& phases = j.at("prediction_by_phase");
  ASSERT_EQ(phases.size(), 8u);
  EXPECT_EQ(phases[3].at("phase"), "tracking");
  EXPECT_NEAR(phases[3].at("duration_s").get<double>(), 20, 1e-9);
  EXPECT_NEAR(phases[3]["horizons"][0]["vs_truth_m"]["rms"].get<double>(), 0.001, 1e-9);
  EXPECT_EQ(phases[3]["horizons"][0]["vs_measurement_m"]["count"].get<int>(), 75);
  EXPECT_TRUE(phases[7].at("duration_s").is_null());  // across phases: no time of its own
  const std::string md = report_markdown(s());
  EXPECT_NE(md.find("| tracking | 20.0 | 1 | 75, 1.00, 1.00, 1.00 | 75, 1.00, 1.00, 1.00 |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| calibration | 10.1 | 16 | "), std::string::npos);
  EXPECT_EQ(md.find("| no grasp machine |"), std::string::npos);
  EXPECT_NE(summary_text(s()).find(
                "prediction h=1 while tracking: RMS 1.00 mm vs measurement, 1.00 mm vs truth"),
            std::string::npos);
}

// Figure 5 leaves out the ball the arm holds: the spans of the calibration and the carried ball.
TEST_F(PhaseErrorTest, HeldSpansForFigureFive) {
  const auto& held = stats_->plot_data().ball_held;
  ASSERT_EQ(held.size(), 2u);
  EXPECT_NEAR(held[0].first, 0, 1e-9);
  EXPECT_NEAR(held[0].second, 10.125, 1e-9);
  EXPECT_NEAR(held[1].first, 33.125, 1e-9);
  EXPECT_NEAR(held[1].second, 45.002, 1e-9);
}

}  // namespace
}  // namespace sg::logger
