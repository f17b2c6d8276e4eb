// sg-predictor: the paper's trajectory prediction (section 5.5). Subscribes to OBJECT_POSITION and
// publishes OBJECT_TRAJECTORY (H points on a fixed period) for every new sample; carries the
// track through occlusions by feeding predictions back. Time comes only from the messages, so a
// replayed log gives the same trajectories.
//
//   sg-predictor                                    # Burg, p = 12, W = 480, 4 Hz, H = 16
//   sg-predictor --model kalman                     # or hold: the baselines
//   sg-predictor --coefficients coeffs.yaml         # start from offline-trained coefficients
//   sg-predictor train session.lcmlog --channel GROUND_TRUTH --out coeffs.yaml
//   sg-predictor train positions.csv --out coeffs.yaml   # lines utime,x,y,z (or t_s,x,y,z)

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <sstream>

#include "common/bus.hpp"
#include "common/message_types.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "predictor/burg.hpp"
#include "predictor/trajectory_message.hpp"
#include "predictor/trajectory_predictor.hpp"

namespace {

using sg::predictor::Forecast;
using sg::predictor::Measurement;
using sg::predictor::PredictorParams;
using sg::predictor::TrackStatus;

PredictorParams load_params(const sg::Config& c) {
  PredictorParams p;
  p.model = sg::predictor::model_from_name(c.get<std::string>("predictor.model", "burg"));
  p.period_us = std::llround(c.get<double>("predictor.period", 0.25) * 1e6);
  p.horizon = c.get<int>("predictor.horizon", p.horizon);
  p.max_gap = c.get<int>("predictor.max_gap", p.max_gap);
  p.burg.order = c.get<int>("predictor.order", p.burg.order);
  p.burg.window = c.get<int>("predictor.window", p.burg.window);
  p.burg.remove_mean = c.get<bool>("predictor.remove_mean", p.burg.remove_mean);
  p.burg.online_after = c.get<int>("predictor.online_after", p.burg.online_after);
  p.gate = c.get<double>("predictor.gate", p.gate);
  p.gate_patience_us = std::llround(c.get<double>("predictor.gate_patience", 0.5) * 1e6);
  if (!(p.gate >= 0)) throw c.error_at("predictor.gate", "must be 0 (off) or positive");
  if (p.gate_patience_us < 0) throw c.error_at("predictor.gate_patience", "must not be negative");
  p.kalman.q = c.get<double>("predictor.kalman_q", p.kalman.q);
  p.kalman.r = c.get<double>("predictor.kalman_r", p.kalman.r);
  if (p.period_us <= 0) throw c.error_at("predictor.period", "must be positive");
  if (p.horizon < 1) throw c.error_at("predictor.horizon", "must be at least 1");
  if (p.burg.order < 1) throw c.error_at("predictor.order", "must be at least 1");
  if (p.burg.window < p.burg.order + 3)
    throw c.error_at("predictor.window", "must exceed the order by 3");
  if (p.burg.online_after < 0 || p.burg.online_after > p.burg.window)
    throw c.error_at("predictor.online_after", "must be 0 to the window's length");
  return p;
}

void load_coefficients(const std::string& path, PredictorParams& p) {
  const sg::Config c = sg::Config::load(path);
  const int order = c.require<int>("order");
  if (order != p.burg.order) {
    spdlog::debug("{}: order {} (the coefficients set the order)", path, order);
    p.burg.order = order;
  }
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

int run(const std::string& url, const PredictorParams& params) {
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  sg::predictor::TrajectoryPredictor predictor(params);
  uint64_t published = 0;
  bus.subscribe<stereograsp::point3_t>(
      "OBJECT_POSITION", [&](const stereograsp::point3_t& m, const auto&) {
        const uint64_t rejected = predictor.rejected();
        const auto forecasts = predictor.add(sg::predictor::measurement_of(m));
        if (predictor.rejected() > rejected &&
            (predictor.rejected() <= 10 || predictor.rejected() % 1000 == 0)) {
          spdlog::warn(
              "OBJECT_POSITION at utime {}: rejected (non-finite, or time not after the last) ({} "
              "so far)",
              m.utime, predictor.rejected());
        }
        for (const Forecast& f : forecasts) {
          bus.publish("OBJECT_TRAJECTORY", sg::predictor::to_trajectory_t(f, params));
          ++published;
        }
      });
  spdlog::info("predicting with {} (period {} ms, horizon {})",
               sg::predictor::model_name(params.model), params.period_us / 1000, params.horizon);
  bus.spin();
  std::printf("published %llu trajectories; %llu measurements rejected\n",
              static_cast<unsigned long long>(published),
              static_cast<unsigned long long>(predictor.rejected()));
  return 0;
}

/// (utime, position) of the visible measurements in a CSV (utime or seconds, x, y, z) or a log.
std::vector<Measurement> read_training(const std::string& input, const std::string& channel) {
  std::vector<Measurement> out;
  if (input.size() > 4 && input.substr(input.size() - 4) == ".csv") {
    std::ifstream file(input);
    if (!file) throw std::runtime_error(input + ": cannot open");
    std::string line;
    for (int number = 1; std::getline(file, line); ++number) {
      if (line.empty() || line[0] == '#' ||
          !(std::isdigit(static_cast<unsigned char>(line[0])) || line[0] == '-'))
        continue;
      std::stringstream s(line);
      double t, x, y, z;
      char c1, c2, c3;
      if (!(s >> t >> c1 >> x >> c2 >> y >> c3 >> z))
        throw std::runtime_error(input + ":" + std::to_string(number) + ": expected t,x,y,z");
      const int64_t utime = t > 1e12 ? static_cast<int64_t>(t) : std::llround(t * 1e6);
      out.push_back({utime, true, {x, y, z}});
    }
    return out;
  }
  lcm::LogFile log(input, "r");
  if (!log.good()) throw std::runtime_error(input + ": cannot open as an LCM log (or give a .csv)");
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel != channel) continue;
    stereograsp::point3_t p;
    if (p.decode(e->data, 0, e->datalen) != e->datalen || !p.visible) continue;
    out.push_back({p.utime, true, {p.position[0], p.position[1], p.position[2]}});
  }
  return out;
}

int train(const std::string& input, const std::string& channel, PredictorParams params,
          const std::string& out) {
  const auto measurements = read_training(input, channel);
  if (measurements.empty()) {
    throw std::runtime_error(input + ": no visible " + channel +
                             " positions (an LCM log with that channel, or a CSV of t,x,y,z)");
  }
  params.model = sg::predictor::Model::kHold;  // only to resample onto the period
  sg::predictor::TrajectoryPredictor resampler(params);
  std::array<std::vector<double>, 3> series;
  for (const Measurement& m : measurements) {
    for (const Forecast& f : resampler.add(m)) {
      if (f.status != TrackStatus::kTracking) continue;
      for (int i = 0; i < 3; ++i) series[static_cast<size_t>(i)].push_back(f.sample[i]);
    }
  }
  const int n = static_cast<int>(series[0].size());
  if (n < 2 * params.burg.order + 3)
    throw std::runtime_error(input + ": " + std::to_string(n) +
                             " samples at the period; need at least " +
                             std::to_string(2 * params.burg.order + 3));
  YAML::Emitter yaml;
  yaml << YAML::BeginMap << YAML::Key << "order" << YAML::Value << params.burg.order << YAML::Key
       << "period" << YAML::Value << params.period_us * 1e-6 << YAML::Key << "samples"
       << YAML::Value << n << YAML::Key << "source" << YAML::Value << input << YAML::Key
       << "coefficients" << YAML::Value << YAML::BeginMap;
  const char* axes[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    std::vector<double> x = series[static_cast<size_t>(i)];
    double mean = 0;
    for (double v : x) mean += v;
    mean /= n;
    for (double& v : x) v -= mean;
    const auto b = sg::predictor::burg(x.data(), n, params.burg.order);
    yaml << YAML::Key << axes[i] << YAML::Value << YAML::Flow << YAML::Precision(17)
         << b.coefficients;
    std::printf("%s: error power %.3g m^2 of %.3g\n", axes[i], b.error_power.back(),
                b.error_power.front());
  }
  yaml << YAML::EndMap << YAML::EndMap;
  std::ofstream file(out + ".tmp");
  file << "# trained by: sg-predictor train " << input << "\n" << yaml.c_str() << "\n";
  file.close();
  if (!file || std::rename((out + ".tmp").c_str(), out.c_str()) != 0)
    throw std::runtime_error(out + ": cannot write");
  std::printf("trained order %d on %d samples from %s; wrote %s\n", params.burg.order, n,
              input.c_str(), out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Predicts the ball's trajectory from OBJECT_POSITION (Burg linear predictors).",
               "sg-predictor"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  std::string model, coefficients;
  int order = 0, window = 0, horizon = 0;
  app.add_option("--model", model, "burg (default), kalman or hold")
      ->check(CLI::IsMember({"burg", "kalman", "hold"}));
  app.add_option("--coefficients", coefficients,
                 "offline-trained coefficients (sg-predictor train)");
  app.add_option("--order", order, "Burg order p (default 12)");
  app.add_option("--window", window, "samples in the sliding window W (default 480)");
  app.add_option("--horizon", horizon, "samples forecast H (default 16)");
  std::string input, out, channel = "OBJECT_POSITION";
  CLI::App* train_cmd =
      app.add_subcommand("train", "Train Burg coefficients offline from a log or a CSV");
  train_cmd->add_option("INPUT", input, "an LCM log, or a CSV of t,x,y,z")->required();
  train_cmd->add_option("--channel", channel, "log channel: OBJECT_POSITION or GROUND_TRUTH");
  train_cmd->add_option("--out", out, "coefficients file to write")->required();

  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    PredictorParams params = load_params(config);
    if (!model.empty()) params.model = sg::predictor::model_from_name(model);
    if (order > 0) params.burg.order = order;
    if (window > 0) params.burg.window = window;
    if (horizon > 0) params.horizon = horizon;
    if (*train_cmd) return train(input, channel, params, out);
    if (coefficients.empty()) coefficients = config.get<std::string>("predictor.coefficients", "");
    if (!coefficients.empty()) load_coefficients(coefficients, params);
    return run(common.lcm_url, params);
  });
}
