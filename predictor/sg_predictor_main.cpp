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

#include <cstdio>

#include "common/bus.hpp"
#include "common/message_types.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "predictor/offline_training.hpp"
#include "predictor/predictor_settings.hpp"
#include "predictor/trajectory_message.hpp"
#include "predictor/trajectory_predictor.hpp"

namespace {

using sg::predictor::Forecast;
using sg::predictor::PredictorParams;

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
  const auto keys = sg::declared_keys(sg::predictor::read_predictor_settings);
  common.flags.add(app, "--model", "predictor.model", keys);
  common.flags.add(app, "--coefficients", "predictor.coefficients", keys);
  common.flags.add(app, "--order", "predictor.order", keys);
  common.flags.add(app, "--window", "predictor.window", keys);
  common.flags.add(app, "--horizon", "predictor.horizon", keys);
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
    return run(common.lcm_url, settings.params);
  });
}
