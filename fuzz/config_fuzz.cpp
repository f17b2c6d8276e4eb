// Drives the configuration loader (common/config.hpp) as every program does: the input is the
// file given to --config, loaded by load_common() (Config::load, the check of the sections
// against config_sections(), the `bus` section), then read by every component's settings reader
// (each program's list, as tests/common/settings_test.cpp has it); and the same bytes as a
// predictor coefficients file (predictor::read_coefficients).
// Asserts, beyond not crashing:
//  - the only error is sg::ConfigError (run_program would turn anything into a one-line error,
//    but a yaml-cpp or std:: exception would not name the file, line and key);
//  - every error names the file: its message starts with the path given.

#include <spdlog/spdlog.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "arm_driver/driver_settings_io.hpp"
#include "arm_driver/kinematics.hpp"
#include "common/bus_check.hpp"
#include "common/config.hpp"
#include "common/program.hpp"
#include "fuzz/fuzz_support.hpp"
#include "grasp/grasp_settings.hpp"
#include "predictor/predictor_settings.hpp"
#include "sim/c550_sim_settings.hpp"
#include "sim/camera_simulator.hpp"
#include "vision/robot_calibration.hpp"
#include "vision/vision_config.hpp"

namespace {

using Reader = std::function<void(const sg::Config&)>;

const std::vector<Reader>& readers() {
  static const std::vector<Reader> all = {
      [](const sg::Config& c) { sg::bus_check::read_send_settings(c); },
      [](const sg::Config& c) { sg::sim::load_sim_params(c); },
      [](const sg::Config& c) { sg::arm::load_arm_geometry(c); },
      [](const sg::Config& c) { sg::sim::read_c550_sim_settings(c); },
      [](const sg::Config& c) { sg::vision::read_vision_settings(c); },
      [](const sg::Config& c) { sg::vision::load_robot_calibration_params(c); },
      [](const sg::Config& c) { sg::predictor::read_predictor_settings(c); },
      [](const sg::Config& c) { sg::arm::read_arm_driver_settings(c); },
      [](const sg::Config& c) { sg::grasp::read_grasp_settings(c); },
  };
  return all;
}

/// Runs `step`; a ConfigError must name `path`, anything else is a finding.
template <class Step>
bool refused(const std::string& path, Step&& step) {
  try {
    step();
    return false;
  } catch (const sg::ConfigError& e) {
    SG_FUZZ_CHECK(std::string(e.what()).starts_with(path), "error without the file: %s", e.what());
    return true;
  } catch (const std::exception& e) {
    SG_FUZZ_CHECK(false, "not a ConfigError: %s", e.what());
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static sg::fuzz::MemoryFile file;
  static const bool quiet = [] {
    spdlog::set_level(spdlog::level::off);
    return true;
  }();
  (void)quiet;
  const std::string& path = file.write(data, size);

  sg::CommonOptions options;
  options.config_path = path;
  options.log_level = "off";
  sg::Config config;
  if (!refused(path, [&] { config = sg::load_common(options); })) {
    for (const Reader& read : readers()) refused(path, [&] { read(config); });
  }
  sg::predictor::PredictorParams params;
  refused(path, [&] { sg::predictor::read_coefficients(path, params); });
  return 0;
}
