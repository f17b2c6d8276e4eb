// Configuration loading: values, defaults, and errors that name file, line and key.

#include "common/config.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/subprocess.hpp"

namespace sg {
namespace {

constexpr const char* kLab = R"(bus:
  url: udpm://239.255.76.67:7667?ttl=1
predictor:
  order: 12
  period: 0.25
  horizon_steps: [1, 4, 16]
  enabled: true
)";

// Dotted keys read values of each type; absent keys give the default.
TEST(Config, ReadsDottedKeysAndDefaults) {
  const Config config = Config::parse(kLab, "lab.yaml");
  EXPECT_EQ(config.get<std::string>("bus.url", ""), "udpm://239.255.76.67:7667?ttl=1");
  EXPECT_EQ(config.require<int>("predictor.order"), 12);
  EXPECT_DOUBLE_EQ(config.get<double>("predictor.period", 1.0), 0.25);
  EXPECT_EQ(config.get<std::vector<int>>("predictor.horizon_steps", {}),
            (std::vector<int>{1, 4, 16}));
  EXPECT_TRUE(config.get<bool>("predictor.enabled", false));
  EXPECT_DOUBLE_EQ(config.get<double>("predictor.absent", 7.5), 7.5);
  EXPECT_DOUBLE_EQ(config.get<double>("absent_section.key", -1.0), -1.0);
  EXPECT_TRUE(config.has("bus.url"));
  EXPECT_FALSE(config.has("bus.port"));
}

// A value of the wrong kind names the file, its line and column, the key and what was found.
TEST(Config, WrongTypeNamesFileLineAndKey) {
  const Config config = Config::parse("predictor:\n  order: twelve\n", "lab.yaml");
  try {
    config.get<int>("predictor.order", 8);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(),
                 "lab.yaml:2:10: key 'predictor.order': expected an integer, got 'twelve'");
  }
}

// A required key that is absent is named.
TEST(Config, MissingRequiredKeyIsNamed) {
  const Config config = Config::parse(kLab, "lab.yaml");
  try {
    config.require<double>("predictor.noise");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "lab.yaml: key 'predictor.noise' is missing");
  }
}

// A key under a scalar is an error, not a silent default.
TEST(Config, KeyUnderAScalarIsAnError) {
  const Config config = Config::parse(kLab, "lab.yaml");
  EXPECT_THROW(config.get<int>("predictor.order.value", 0), ConfigError);
}

// Invalid YAML names the file and the line of the problem.
TEST(Config, InvalidYamlNamesLine) {
  try {
    Config::parse("bus:\n  url: x\n  list: [1, 2\n", "bad.yaml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bad.yaml:", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("not valid YAML"), std::string::npos) << e.what();
  }
}

// A top level that is not a map is refused; an empty file is an empty configuration.
TEST(Config, TopLevelMustBeAMap) {
  EXPECT_THROW(Config::parse("- 1\n- 2\n", "list.yaml"), ConfigError);
  EXPECT_EQ(Config::parse("", "empty.yaml").get<int>("a.b", 3), 3);
}

// A file that cannot be opened is named.
TEST(Config, MissingFileIsNamed) {
  try {
    Config::load("/nonexistent/stereograsp.yaml");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/stereograsp.yaml: cannot open configuration file");
  }
}

// load() reads a real file and reports its path in errors.
TEST(Config, LoadsAFile) {
  const std::string path = test::make_temp_dir() + "/lab.yaml";
  std::ofstream(path) << kLab;
  const Config config = Config::load(path);
  EXPECT_EQ(config.require<int>("predictor.order"), 12);
  EXPECT_EQ(config.source(), path);
  const ConfigError error = config.error_at("predictor.order", "must be at most 10");
  EXPECT_EQ(std::string(error.what()), path + ":4:10: key 'predictor.order': must be at most 10");
}

// The shipped default configuration parses and holds the keys programs read.
TEST(Config, ShippedDefaultsParse) {
  const Config config = Config::load(std::string(SG_SOURCE_DIR) + "/config/stereograsp.yaml");
  EXPECT_GT(config.require<double>("bus_check.rate_hz"), 0.0);
  EXPECT_GT(config.require<int64_t>("bus_check.count"), 0);
}

}  // namespace
}  // namespace sg
