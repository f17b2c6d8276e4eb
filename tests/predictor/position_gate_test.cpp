// The plausibility gate in front of the predictor, and the predictor's own recovery: the measured
// defect (a second of 1e300 positions poisoned the predictor until a restart), NaN, infinities,
// positions outside the workspace, capture times far from the receiver's clock; each refused and
// counted, none entering the predictor's history.

#include "predictor/position_gate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/clock.hpp"
#include "common/config.hpp"
#include "predictor/predictor_node.hpp"
#include "predictor/predictor_settings.hpp"
#include "predictor/trajectory_predictor.hpp"

namespace sg::predictor {
namespace {

constexpr int64_t kT0 = 1'800'000'000'000'000;  // 2027-01-15, us
constexpr int64_t kFrame = 33'333;              // sg-vision's 30 Hz

/// A clock the test sets: utime() is what the test says, now() follows it.
class TestClock final : public Clock {
 public:
  double now() override { return static_cast<double>(utime_) * 1e-6; }
  int64_t utime() override { return utime_; }
  bool wait_until(std::unique_lock<std::mutex>&, double, const std::function<bool()>& ready,
                  std::stop_token) override {
    return ready();
  }
  void notify() override {}
  void sleep_until(double) override {}
  void set(int64_t utime) { utime_ = utime; }

 private:
  int64_t utime_ = kT0;
};

/// The paper's motion: a 0.15 m circle at 1 rpm around (0.45, 0, 0.10), at time s seconds.
Eigen::Vector3d circle(double s) {
  const double w = 2 * M_PI / 60;
  return {0.45 + 0.15 * std::cos(w * s), 0.15 * std::sin(w * s), 0.10};
}

stereograsp::point3_t position(int64_t utime, const Eigen::Vector3d& p, bool visible = true) {
  stereograsp::point3_t m{};
  m.utime = utime;
  m.visible = visible;
  for (int i = 0; i < 3; ++i) m.position[i] = p[i];
  return m;
}

/// The shipped defaults: the A465's workspace, margin 0.25 m, +-5 s.
PredictorSettings defaults() { return read_predictor_settings(Config()); }

bool finite_and_near(const stereograsp::trajectory_t& t, const Eigen::Vector3d& ball, double tol) {
  if (t.status == stereograsp::trajectory_t::STATUS_LOST || t.position.empty()) return false;
  for (const auto& q : t.position) {
    const Eigen::Vector3d p(q[0], q[1], q[2]);
    if (!p.allFinite() || (p - ball).norm() > tol) return false;
  }
  return true;
}

/// Feeds `seconds` of the circle at 30 Hz from frame `k` on, the clock at each capture time;
/// returns the trajectories published.
std::vector<stereograsp::trajectory_t> feed(PredictorNode& node, TestClock& clock, int& k,
                                            double seconds) {
  std::vector<stereograsp::trajectory_t> out;
  for (int n = 0; n < static_cast<int>(seconds * 30); ++n, ++k) {
    const int64_t t = kT0 + k * kFrame;
    clock.set(t + 20'000);  // received 20 ms after capture
    for (auto& tr : node.on_position(position(t, circle(k / 30.0))).trajectories)
      out.push_back(std::move(tr));
  }
  return out;
}

// The gate's defaults come from the arm's workspace (arm.workspace_min/max), the one definition.
TEST(PositionGate, TheBoxIsTheArmsWorkspace) {
  const PredictorSettings s =
      read_predictor_settings(Config::parse("arm:\n  workspace_min: [-0.5, -0.6, 0.0]\n"));
  EXPECT_EQ(s.gate.box_min, Eigen::Vector3d(-0.5, -0.6, 0.0));
  EXPECT_EQ(s.gate.box_max, Eigen::Vector3d(0.90, 0.90, 1.25));  // the A465's
  EXPECT_DOUBLE_EQ(s.gate.margin, 0.25);
  EXPECT_EQ(s.gate.max_time_offset_us, 5'000'000);
}

// NaN, an infinity, a point outside the box plus margin, a time 6 s in the past and in the future:
// each refused with its reason and counted; inside the margin and 4 s off is accepted.
TEST(PositionGate, RefusesAndCountsEachReason) {
  PositionGate gate(defaults().gate);
  const int64_t now = kT0;
  const Eigen::Vector3d ok(0.45, 0, 0.1);
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(gate.check({now, true, ok}, now));
  EXPECT_FALSE(gate.check({now, true, {1.14, -1.14, -0.19}}, now));  // inside the 0.25 m margin
  EXPECT_FALSE(gate.check({now - 4'000'000, true, ok}, now));
  EXPECT_FALSE(gate.check({now, false, {nan, nan, nan}}, now));  // not seen: no position to check
  EXPECT_EQ(gate.check({now, true, {nan, 0, 0}}, now), PositionRefusal::kNonFinite);
  EXPECT_EQ(gate.check({now, true, {0, inf, 0}}, now), PositionRefusal::kNonFinite);
  EXPECT_EQ(gate.check({now, true, {1e300, 0, 0}}, now), PositionRefusal::kOutsideWorkspace);
  EXPECT_EQ(gate.check({now, true, {0.45, 0, 1.51}}, now), PositionRefusal::kOutsideWorkspace);
  EXPECT_EQ(gate.check({now, true, {0.45, 0, -0.21}}, now), PositionRefusal::kOutsideWorkspace);
  EXPECT_NE(gate.last_refusal().find("outside the workspace"), std::string::npos);
  EXPECT_EQ(gate.check({now - 6'000'000, true, ok}, now), PositionRefusal::kTimeFarFromNow);
  EXPECT_EQ(gate.check({now + 6'000'000, false, ok}, now), PositionRefusal::kTimeFarFromNow);
  EXPECT_EQ(gate.check({std::numeric_limits<int64_t>::max(), true, ok}, now),
            PositionRefusal::kTimeFarFromNow);
  EXPECT_EQ(gate.check({std::numeric_limits<int64_t>::min(), true, ok}, now),
            PositionRefusal::kTimeFarFromNow);
  EXPECT_EQ(gate.refused(PositionRefusal::kNonFinite), 2u);
  EXPECT_EQ(gate.refused(PositionRefusal::kOutsideWorkspace), 3u);
  EXPECT_EQ(gate.refused(PositionRefusal::kTimeFarFromNow), 4u);
  EXPECT_EQ(gate.counts_text(), "non-finite 2, outside the workspace 3, time far from now 4");
}

// max_time_offset 0 turns the time check off (replays of old logs), not the position checks.
TEST(PositionGate, ZeroOffsetTurnsTheTimeCheckOff) {
  PositionGateParams p = defaults().gate;
  p.max_time_offset_us = 0;
  PositionGate gate(p);
  EXPECT_FALSE(gate.check({1'700'000'000'000'000, true, {0.45, 0, 0.1}}, kT0));
  EXPECT_EQ(gate.check({1'700'000'000'000'000, true, {5, 0, 0.1}}, kT0),
            PositionRefusal::kOutsideWorkspace);
}

// The measured case: a minute of the circle, one second of finite 1e300 positions at 30 Hz, then
// the circle again. The gate refuses all 30 (counted), none reaches the predictor, and the
// trajectories on either side are finite and on the ball.
TEST(PredictorNode, ASecondOf1e300IsRefusedAndTheTrajectoriesStayGood) {
  TestClock clock;
  PredictorNode node(defaults(), clock);
  int k = 0;
  feed(node, clock, k, 60);
  for (int n = 0; n < 30; ++n, ++k) {
    const int64_t t = kT0 + k * kFrame;
    clock.set(t);
    const PredictorNode::Output out = node.on_position(position(t, {1e300, 1e300, 1e300}));
    EXPECT_TRUE(out.trajectories.empty());
    EXPECT_NE(out.refused.find("outside the workspace"), std::string::npos) << out.refused;
  }
  EXPECT_EQ(node.gate().refused(PositionRefusal::kOutsideWorkspace), 30u);
  const auto after = feed(node, clock, k, 5);
  ASSERT_GE(after.size(), 19u);
  for (const auto& t : after) EXPECT_TRUE(finite_and_near(t, circle(k / 30.0), 0.5));
  EXPECT_EQ(node.predictor().resets(), 0u);
  EXPECT_NE(node.status_line().find("outside the workspace 30"), std::string::npos);
}

// Without the gate, the predictor recovers by itself: 1e300 samples fail its sanity check, it
// resets (a lost forecast, counted, with the reason) and, within a second of good positions, its
// trajectories are finite and on the ball again; before the fix they stayed near 1e298 for the
// 2-minute window.
TEST(TrajectoryPredictor, RecoversOnItsOwnFrom1e300) {
  TrajectoryPredictor predictor{PredictorParams{}};
  int k = 0;
  const auto add = [&](const Eigen::Vector3d& p) {
    return predictor.add({kT0 + k++ * kFrame, true, p});
  };
  for (int n = 0; n < 60 * 30; ++n) add(circle(k / 30.0));
  bool lost = false;
  for (int n = 0; n < 30; ++n) {
    for (const Forecast& f : add({1e300, 1e300, 1e300})) {
      lost |= f.status == TrackStatus::kLost;
      for (const auto& q : f.positions) EXPECT_LE((q - f.sample).norm(), 10.0);
    }
  }
  EXPECT_TRUE(lost);
  EXPECT_GE(predictor.resets(), 1u);
  EXPECT_NE(predictor.last_reset().find("m of the base"), std::string::npos)
      << predictor.last_reset();
  const uint64_t resets = predictor.resets();
  int good = 0, samples = 0;
  for (int n = 0; n < 10 * 30; ++n) {
    for (const Forecast& f : add(circle(k / 30.0))) {
      ++samples;
      bool ok = f.status == TrackStatus::kTracking && !f.positions.empty();
      for (const auto& q : f.positions) ok &= q.allFinite() && (q - circle(k / 30.0)).norm() < 0.5;
      if (samples > 4) {
        EXPECT_TRUE(ok) << "sample " << samples;  // within 4 samples (1 s)
      }
      good += ok;
    }
  }
  EXPECT_LE(predictor.resets(), resets + 1);  // at most once more, at the jump back
  EXPECT_GE(good, samples - 4);
}

// Extreme but in-range jumps (between two far corners of the workspace every 4 frames) whose
// forecast leaves the reset distance (a constant-velocity model extrapolates them 11.9 m over
// 4 s) reset the predictor, which then starts again on the circle.
TEST(TrajectoryPredictor, AnAbsurdForecastResets) {
  PredictorParams p;
  p.model = Model::kKalman;
  p.gate = 0;  // no gate: the step is taken as the ball's
  p.reset_distance = 5.0;
  TrajectoryPredictor predictor(p);
  int k = 0;
  for (int n = 0; n < 200; ++n) predictor.add({kT0 + k++ * kFrame, true, circle(k / 30.0)});
  EXPECT_EQ(predictor.resets(), 0u);
  bool lost = false;
  for (int n = 0; n < 60 && !lost; ++n) {
    const Eigen::Vector3d corner =
        n % 8 < 4 ? Eigen::Vector3d(1.1, -0.9, 0.1) : Eigen::Vector3d(-0.9, 0.9, 1.2);
    for (const Forecast& f : predictor.add({kT0 + k++ * kFrame, true, corner}))
      lost |= f.status == TrackStatus::kLost;
  }
  EXPECT_TRUE(lost);
  EXPECT_EQ(predictor.resets(), 1u);
  EXPECT_NE(predictor.last_reset().find("forecast point"), std::string::npos)
      << predictor.last_reset();
  size_t tracking = 0;
  for (int n = 0; n < 30; ++n) {
    for (const Forecast& f : predictor.add({kT0 + k++ * kFrame, true, circle(k / 30.0)}))
      tracking += f.status == TrackStatus::kTracking;
  }
  EXPECT_GE(tracking, 3u);
}

// A clock stepped back (or a log replayed again): after kMaxBackwardRun refused times in a row
// the predictor starts again rather than refuse forever.
TEST(TrajectoryPredictor, AClockSteppedBackRecovers) {
  TrajectoryPredictor predictor{PredictorParams{}};
  for (int k = 0; k < 100; ++k) predictor.add({kT0 + k * kFrame, true, circle(k / 30.0)});
  const int64_t back = kT0 - 3'600'000'000;
  size_t forecasts = 0;
  for (int k = 0; k < TrajectoryPredictor::kMaxBackwardRun + 20; ++k)
    forecasts += predictor.add({back + k * kFrame, true, circle(k / 30.0)}).size();
  EXPECT_EQ(predictor.rejected(), static_cast<uint64_t>(TrajectoryPredictor::kMaxBackwardRun - 1));
  EXPECT_EQ(predictor.resets(), 1u);
  EXPECT_GT(forecasts, 3u);
  EXPECT_EQ(predictor.status(), TrackStatus::kTracking);
}

// Through the node: NaN, infinity, out of the box, 10 s in the past and the future, each counted
// under its reason; a future time never enters the history (the next good position is taken).
TEST(PredictorNode, EachReasonIsCountedAndNothingEntersTheHistory) {
  TestClock clock;
  PredictorNode node(defaults(), clock);
  int k = 0;
  feed(node, clock, k, 10);
  const int64_t t = kT0 + k * kFrame;
  clock.set(t);
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  EXPECT_NE(node.on_position(position(t, {nan, 0, 0})).refused, "");
  EXPECT_NE(node.on_position(position(t, {0, -inf, 0})).refused, "");
  EXPECT_NE(node.on_position(position(t, {3, 0, 0})).refused, "");
  EXPECT_NE(node.on_position(position(t - 10'000'000, circle(k / 30.0))).refused, "");
  EXPECT_NE(node.on_position(position(t + 10'000'000, circle(k / 30.0))).refused, "");
  EXPECT_EQ(node.gate().refused(PositionRefusal::kNonFinite), 2u);
  EXPECT_EQ(node.gate().refused(PositionRefusal::kOutsideWorkspace), 1u);
  EXPECT_EQ(node.gate().refused(PositionRefusal::kTimeFarFromNow), 2u);
  EXPECT_EQ(node.predictor().rejected(), 0u);
  const auto after = feed(node, clock, k, 2);  // taken: the future time did not become "the last"
  EXPECT_GE(after.size(), 7u);
  for (const auto& tr : after) EXPECT_TRUE(finite_and_near(tr, circle(k / 30.0), 0.5));
  EXPECT_EQ(node.status_line(),
            "OBJECT_POSITION refused: non-finite 2, outside the workspace 1, time far from now 2, "
            "not after the last 0; predictor resets 0");
}

// The output channel is OBJECT_TRAJECTORY unless set; a name LCM cannot carry, or one that is
// empty, is refused naming the key.
TEST(PredictorSettings, OutputChannelIsCheckedAsAChannelName) {
  EXPECT_EQ(read_predictor_settings(Config()).output_channel, "OBJECT_TRAJECTORY");
  EXPECT_EQ(read_predictor_settings(
                Config::parse("predictor:\n  output_channel: OBJECT_TRAJECTORY_LOCAL\n"))
                .output_channel,
            "OBJECT_TRAJECTORY_LOCAL");
  for (const std::string& bad :
       std::vector<std::string>{"\"\"", "\"A B\"", "\"A;rm\"", std::string(64, 'A')}) {
    SCOPED_TRACE(bad);
    try {
      read_predictor_settings(Config::parse("predictor:\n  output_channel: " + bad + "\n"));
      ADD_FAILURE() << "accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("output_channel"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(valid_channel_name(std::string(63, 'A')));
  EXPECT_TRUE(valid_channel_name("BUS_CHECK_point3.t-1"));
}

}  // namespace
}  // namespace sg::predictor
