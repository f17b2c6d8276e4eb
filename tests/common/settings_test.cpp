// Every component's settings reader against the shipped config/stereograsp.yaml: it loads clean
// for every program, it holds the structs' own defaults, and a typo in any section is caught.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "arm_driver/driver_settings_io.hpp"
#include "arm_driver/kinematics.hpp"
#include "common/bus_check.hpp"
#include "common/config.hpp"
#include "common/program.hpp"
#include "grasp/grasp_settings.hpp"
#include "predictor/predictor_settings.hpp"
#include "sim/c550_sim_settings.hpp"
#include "sim/camera_simulator.hpp"
#include "tests/support/subprocess.hpp"
#include "vision/robot_calibration.hpp"
#include "vision/vision_config.hpp"

namespace sg {
namespace {

using Reader = std::function<void(const Config&)>;

/// The readers each program runs after load_common().
const std::map<std::string, std::vector<Reader>>& programs() {
  static const std::map<std::string, std::vector<Reader>> readers = {
      {"sg-bus-check", {[](const Config& c) { bus_check::read_send_settings(c); }}},
      {"sg-camera-sim", {[](const Config& c) { sim::load_sim_params(c); }}},
      {"sg-c550-sim",
       {[](const Config& c) { arm::load_arm_geometry(c); },
        [](const Config& c) { sim::read_c550_sim_settings(c); }}},
      {"sg-vision", {[](const Config& c) { vision::read_vision_settings(c); }}},
      {"sg-calibrate", {[](const Config& c) { vision::load_robot_calibration_params(c); }}},
      {"sg-predictor", {[](const Config& c) { predictor::read_predictor_settings(c); }}},
      {"sg-arm-driver",
       {[](const Config& c) { arm::load_arm_geometry(c); },
        [](const Config& c) { arm::read_arm_driver_settings(c); }}},
      {"sg-grasp",
       {[](const Config& c) { arm::load_arm_geometry(c); },
        [](const Config& c) { grasp::read_grasp_settings(c); }}},
  };
  return readers;
}

const std::string kShipped = std::string(SG_SOURCE_DIR) + "/config/stereograsp.yaml";

Config load_as_a_program(const std::string& path) {
  CommonOptions options;
  options.config_path = path;
  return load_common(options);
}

/// Every key any reader declares (run on an empty configuration, so with the defaults).
std::vector<KeyInfo> all_keys() {
  const Config probe;
  for (const auto& [name, readers] : programs()) {
    for (const Reader& read : readers) read(probe);
  }
  return probe.declared_keys();
}

// The shipped file loads clean through every program's readers: no unknown section or key.
TEST(Settings, ShippedConfigLoadsCleanForEveryProgram) {
  for (const auto& [name, readers] : programs()) {
    SCOPED_TRACE(name);
    const Config config = load_as_a_program(kShipped);
    for (const Reader& read : readers) EXPECT_NO_THROW(read(config));
  }
}

// Every section load_common() accepts is read by some reader, and every key of the shipped file
// is one a reader declares.
TEST(Settings, EverySectionHasAReader) {
  const std::vector<KeyInfo> keys = all_keys();
  for (const std::string& section : config_sections()) {
    if (section == "bus") continue;  // load_common's own
    const bool read = std::any_of(keys.begin(), keys.end(), [&](const KeyInfo& k) {
      return k.key.rfind(section + ".", 0) == 0;
    });
    EXPECT_TRUE(read) << section;
  }
}

/// The numbers in text such as "0.1" or "[0.45, 0, 0.1]"; empty when it holds none.
std::vector<double> numbers_in(const std::string& text) {
  std::vector<double> out;
  std::string cleaned = text;
  for (char& c : cleaned) c = (c == '[' || c == ']' || c == ',') ? ' ' : c;
  std::istringstream in(cleaned);
  std::string word;
  while (in >> word) {
    try {
      size_t used = 0;
      out.push_back(std::stod(word, &used));
      if (used != word.size()) return {};
    } catch (const std::exception&) {
      return {};
    }
  }
  return out;
}

// config/stereograsp.yaml repeats the built-in defaults: each key it holds has the struct's value.
TEST(Settings, ShippedConfigHoldsTheDefaults) {
  const Config shipped = Config::load(kShipped);
  for (const KeyInfo& k : all_keys()) {
    if (!shipped.has(k.key) || k.arity == 0) continue;  // a table: its reader's own tests
    SCOPED_TRACE(k.key);
    const std::vector<double> expected = numbers_in(k.default_text);
    ASSERT_TRUE(!expected.empty() || k.arity == 1) << "a list without numbers: " << k.default_text;
    if (!expected.empty()) {
      const auto actual = expected.size() == 1 && k.arity == 1
                              ? std::vector<double>{shipped.require<double>(k.key)}
                              : shipped.require<std::vector<double>>(k.key);
      ASSERT_EQ(actual.size(), expected.size());
      for (size_t i = 0; i < actual.size(); ++i) EXPECT_NEAR(actual[i], expected[i], 1e-12);
    } else if (k.default_text == "\"\"") {
      EXPECT_EQ(shipped.require<std::string>(k.key), "");
    } else {
      EXPECT_EQ(shipped.require<std::string>(k.key), k.default_text);
    }
  }
}

// A typo in any key of any section is refused by the program that reads it, with the nearest.
TEST(Settings, ATypoInEverySectionIsCaught) {
  for (const auto& [name, readers] : programs()) {
    const Config probe;
    for (const Reader& read : readers) read(probe);
    for (const KeyInfo& k : probe.declared_keys()) {
      const std::string section = k.key.substr(0, k.key.find('.'));
      const std::string leaf = k.key.substr(k.key.find('.') + 1);
      const std::string typo = leaf + "x";  // one letter too many
      const Config config = Config::parse(section + ":\n  " + typo + ": 1\n", "lab.yaml");
      std::string error;
      try {
        for (const Reader& read : readers) read(config);
      } catch (const ConfigError& e) {
        error = e.what();
      }
      EXPECT_EQ(error.rfind("lab.yaml:2:3: unknown key '" + section + "." + typo + "'", 0), 0u)
          << name << " " << k.key << ": " << error;
      EXPECT_NE(error.find("(did you mean '"), std::string::npos) << error;
    }
  }
}

// load_common() refuses a misspelt section whatever the program.
TEST(Settings, LoadCommonRefusesAnUnknownSection) {
  const std::string path = test::make_temp_dir() + "/lab.yaml";
  std::ofstream(path) << "bus:\n  url: ''\n\npredictr:\n  order: 8\n";
  try {
    load_as_a_program(path);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              path + ":4:1: unknown section 'predictr' (did you mean 'predictor'?)");
  }
}

// A program's --help shows the settings struct's defaults beside the flags that set them.
TEST(Settings, HelpShowsTheStructsDefaults) {
  const auto help = [](const std::string& program) {
    return test::run({test::program(program), "--help"}).out;
  };
  const std::string grasp = help("sg-grasp");
  EXPECT_NE(grasp.find("--standoff VALUE=" + show(grasp::GraspSettings{}.standoff)),
            std::string::npos)
      << grasp;
  EXPECT_NE(grasp.find("config grasp.standoff; must be in [0, 0.5]"), std::string::npos);
  const std::string predictor = help("sg-predictor");
  EXPECT_NE(predictor.find("--order VALUE=" + std::to_string(predictor::BurgParams{}.order)),
            std::string::npos)
      << predictor;
  const std::string c550 = help("sg-c550-sim");
  EXPECT_NE(c550.find("--delay-max VALUE=" + show(sim::C550Params{}.delay_max)), std::string::npos)
      << c550;
}

}  // namespace
}  // namespace sg
