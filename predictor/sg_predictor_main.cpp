// sg-predictor: the paper's trajectory prediction (section 5.5). Subscribes to OBJECT_POSITION and
// publishes OBJECT_TRAJECTORY (H points on a fixed period) for every new sample; carries the
// track through occlusions by feeding predictions back. Time comes only from the messages, so a
// replayed log gives the same trajectories. Positions that are not finite, outside the arm's
// workspace plus a margin, or captured far from the receiver's clock are refused and counted
// (docs/prediction.md; --max-time-offset 0 for replays of old logs).
//
//   sg-predictor                                    # Burg, p = 12, W = 480, 4 Hz, H = 16
//   sg-predictor --model kalman                     # or hold: the baselines
//   sg-predictor --coefficients coeffs.yaml         # start from offline-trained coefficients
//   sg-predictor --model kalman --output-channel OBJECT_TRAJECTORY_KALMAN   # a baseline beside
//   sg-predictor train session.lcmlog --channel GROUND_TRUTH --out coeffs.yaml
//   sg-predictor train positions.csv --out coeffs.yaml   # lines utime,x,y,z (or t_s,x,y,z)

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>

#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "predictor/offline_training.hpp"
#include "predictor/predictor_node.hpp"
#include "predictor/predictor_settings.hpp"
#include "predictor/trajectory_message.hpp"
#include "predictor/trajectory_predictor.hpp"

namespace {

using sg::predictor::PredictorParams;

/// Seconds between the status lines that report new refusals.
constexpr double kStatusPeriod = 10.0;

int run(const std::string& url, const sg::predictor::PredictorSettings& settings,
        const sg::auth::LabAccess& lab) {
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  lab.guard(bus);                // believes OBJECT_POSITION only from sg-vision
  bus.announce("sg-predictor");  // PROCESS_STATUS: the refusals counted with note_refused()
  sg::Clock& clock = sg::system_clock();
  sg::predictor::PredictorNode node(settings, clock);
  bus.subscribe<stereograsp::point3_t>(
      "OBJECT_POSITION", [&](const stereograsp::point3_t& m, const auto&) {
        const sg::predictor::PredictorNode::Output out = node.on_position(m);
        if (!out.refused.empty()) bus.note_refused("OBJECT_POSITION", out.refused);
        if (!out.reset.empty()) spdlog::warn("predictor reset itself: {}", out.reset);
        for (const auto& t : out.trajectories) bus.publish(settings.output_channel, t);
      });
  const PredictorParams& params = settings.params;
  spdlog::info("predicting with {} (period {} ms, horizon {}) on {}",
               sg::predictor::model_name(params.model), params.period_us / 1000, params.horizon,
               settings.output_channel);
  std::string reported = node.status_line();
  double next_report = clock.now() + kStatusPeriod;
  bus.spin([&] {  // the refusals by reason, when they changed, at most every kStatusPeriod
    if (clock.now() < next_report) return true;
    next_report = clock.now() + kStatusPeriod;
    if (const std::string line = node.status_line(); line != reported) {
      spdlog::warn("{}", line);
      reported = line;
    }
    return true;
  });
  std::printf("published %llu trajectories; %llu measurements rejected\n%s\n",
              static_cast<unsigned long long>(node.published()),
              static_cast<unsigned long long>(node.gate().refused() + node.predictor().rejected()),
              node.status_line().c_str());
  return 0;
}

/// Trains Burg coefficients from `input` (a .csv, else an LCM log) and writes them to `out`.
int train(const std::string& input, const std::string& channel, const PredictorParams& params,
          const std::string& out) {
  const bool csv = input.size() > 4 && input.substr(input.size() - 4) == ".csv";
  const auto measurements = csv ? sg::predictor::read_training_csv(input)
                                : sg::predictor::read_training_log(input, channel);
  if (measurements.empty()) {
    throw std::runtime_error(input + ": no visible " + channel +
                             " positions (an LCM log with that channel, or a CSV of t,x,y,z)");
  }
  sg::predictor::TrainedCoefficients trained;
  try {
    trained = sg::predictor::train_coefficients(measurements, params);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(input + ": " + e.what());
  }
  const char* axes[3] = {"x", "y", "z"};
  for (size_t i = 0; i < 3; ++i) {
    std::printf("%s: error power %.3g m^2 of %.3g\n", axes[i], trained.error_power[i].back(),
                trained.error_power[i].front());
  }
  sg::predictor::write_coefficients(out, trained, input);
  std::printf("trained order %d on %d samples from %s; wrote %s\n", trained.order, trained.samples,
              input.c_str(), out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Predicts the ball's trajectory from OBJECT_POSITION (Burg linear predictors).",
               "sg-predictor"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  const auto keys = sg::declared_keys(sg::predictor::read_predictor_settings);
  common.flags.add(app, "--model", "predictor.model", keys);
  common.flags.add(app, "--coefficients", "predictor.coefficients", keys);
  common.flags.add(app, "--order", "predictor.order", keys);
  common.flags.add(app, "--window", "predictor.window", keys);
  common.flags.add(app, "--horizon", "predictor.horizon", keys);
  common.flags.add(app, "--max-time-offset", "predictor.max_time_offset", keys);
  common.flags.add(app, "--output-channel", "predictor.output_channel", keys);
  std::string input, out, channel = "OBJECT_POSITION";
  CLI::App* train_cmd =
      app.add_subcommand("train", "Train Burg coefficients offline from a log or a CSV");
  train_cmd->add_option("INPUT", input, "an LCM log, or a CSV of t,x,y,z")->required();
  train_cmd->add_option("--channel", channel, "log channel: OBJECT_POSITION or GROUND_TRUTH");
  train_cmd->add_option("--out", out, "coefficients file to write")->required();

  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    sg::predictor::PredictorSettings settings = sg::predictor::read_predictor_settings(config);
    if (*train_cmd) return train(input, channel, settings.params, out);
    if (!settings.coefficients.empty())
      sg::predictor::read_coefficients(settings.coefficients, settings.params);
    return sg::auth::with_lab_access(app.get_name(), key_options,
                                     [&](auto& lab) { return run(common.lcm_url, settings, lab); });
  });
}
