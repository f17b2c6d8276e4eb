#include "predictor/predictor_settings.hpp"

#include <cmath>
#include <stdexcept>

#include "arm_driver/kinematics.hpp"

namespace sg::predictor {
namespace {

/// Microseconds read as seconds, in `range` (seconds).
void seconds_key(Section& section, const std::string& key, int64_t& us, const Range& range,
                 const std::string& help) {
  double seconds = static_cast<double>(us) * 1e-6;
  section.number(key, seconds, range, help);
  us = std::llround(seconds * 1e6);
}

}  // namespace

bool valid_channel_name(const std::string& name) {
  if (name.empty() || name.size() > 63) return false;
  for (const char ch : name) {
    const bool ok = (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') ||
                    (ch >= '0' && ch <= '9') || ch == '_' || ch == '-' || ch == '.';
    if (!ok) return false;
  }
  return true;
}

PredictorSettings read_predictor_settings(const Config& config) {
  PredictorSettings s;
  PredictorParams& p = s.params;
  Section c(config, "predictor");
  std::string model = model_name(p.model);
  c.choice("model", model, {"burg", "kalman", "hold"}, "burg, or the baselines kalman and hold");
  p.model = model_from_name(model);
  seconds_key(c, "period", p.period_us, Range::closed(0.001, 60), "s: the sample period");
  c.number("horizon", p.horizon, Range::closed(1, kMaxHorizon), "samples forecast H");
  c.number("max_gap", p.max_gap, Range::closed(0, 10000),
           "fed-back samples through an occlusion before the track is lost");
  c.number("order", p.burg.order, Range::closed(1, 100), "Burg's order p");
  c.number("window", p.burg.window, Range::closed(4, 100000), "samples in the sliding window W");
  if (p.burg.window < p.burg.order + 3) throw c.error("window", "must exceed the order by 3");
  c.flag("remove_mean", p.burg.remove_mean, "Burg models a zero-mean signal");
  c.text("coefficients", s.coefficients,
         "offline-trained coefficients (sg-predictor train); \"\" = learn online");
  c.number("online_after", p.burg.online_after, Range::closed(0, 100000),
           "with coefficients: samples before online estimates replace them");
  if (p.burg.online_after > p.burg.window)
    throw c.error("online_after", "must be 0 to the window's length");
  c.number("gate", p.gate, Range::closed(0, 10),
           "m: while tracking, a measurement this far from the forecast is taken as not seen "
           "(0: off)");
  seconds_key(c, "gate_patience", p.gate_patience_us, Range::closed(0, 600),
              "s: ... unless measurements disagree for this long");
  c.number("kalman_q", p.kalman.q, Range::above_to(0, 1e3),
           "kalman: white-acceleration spectral density (m^2/s^3)");
  c.number("kalman_r", p.kalman.r, Range::above_to(0, 10), "kalman: measurement noise (m)");
  c.number("reset_distance", p.reset_distance, Range::closed(0.1, 1000),
           "m: a sample this far from the base, or a forecast point this far from the newest "
           "sample (or not finite), resets the predictor");
  PositionGateParams& g = s.gate;
  c.number("position_margin", g.margin, Range::closed(0, 2),
           "m: an OBJECT_POSITION farther than this outside the arm's workspace "
           "(arm.workspace_min/max) is refused");
  seconds_key(c, "max_time_offset", g.max_time_offset_us, Range::closed(0, 3600),
              "s: an OBJECT_POSITION whose capture time is farther than this from the receiver's "
              "clock is refused (0: not checked, for replays of old logs)");
  c.text("output_channel", s.output_channel,
         "the channel the trajectories go out on (sg-grasp follows OBJECT_TRAJECTORY)");
  if (!valid_channel_name(s.output_channel))
    throw c.error("output_channel", "must be 1 to 63 letters, digits, '_', '-' or '.'");
  c.done();
  const arm::Workspace workspace = arm::load_arm_geometry(config).workspace;
  g.box_min = workspace.min;
  g.box_max = workspace.max;
  return s;
}

void read_coefficients(const std::string& path, PredictorParams& p) {
  const Config c = Config::load(path);
  const int order = c.require<int>("order");
  if (order < 1) throw c.error_at("order", "must be at least 1");
  p.burg.order = order;
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    const std::string key = std::string("coefficients.") + axes[i];
    auto a = c.require<std::vector<double>>(key);
    if (static_cast<int>(a.size()) != order) throw c.error_at(key, "must hold `order` numbers");
    for (double v : a) {
      if (!std::isfinite(v)) throw c.error_at(key, "holds a non-finite number");
    }
    p.initial_coefficients[static_cast<size_t>(i)] = a;
  }
}

}  // namespace sg::predictor
