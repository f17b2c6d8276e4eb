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

// A key no reader knows names the file, its line and column, the key and the nearest known key.
TEST(Config, UnknownKeyIsNamedWithTheNearest) {
  const Config config = Config::parse("grasp:\n  standoff: 0.1\n  stanoff: 0.2\n", "lab.yaml");
  double standoff = 0.1, lift = 0.15;
  Section grasp(config, "grasp");
  grasp.number("standoff", standoff, Range::closed(0, 0.5), "m");
  grasp.number("lift", lift, Range::above(0), "m");
  try {
    grasp.done();
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(),
                 "lab.yaml:3:3: unknown key 'grasp.stanoff' (did you mean "
                 "'grasp.standoff'?)");
  }
}

// A misspelt section is refused with its line and the nearest section.
TEST(Config, UnknownSectionIsNamedWithTheNearest) {
  const Config config = Config::parse("bus:\n  url: ''\ngasp:\n  standoff: 0.1\n", "lab.yaml");
  try {
    config.reject_unknown_sections({"bus", "grasp", "predictor"});
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "lab.yaml:3:1: unknown section 'gasp' (did you mean 'grasp'?)");
  }
  EXPECT_NO_THROW(config.reject_unknown_sections({"bus", "gasp"}));
}

// NaN, an infinity and a value out of range are refused with the file, line, key and value.
TEST(Config, OutOfRangeAndNanAreRefused) {
  const auto error = [](const std::string& value) {
    const Config config = Config::parse("grasp:\n  speed: " + value + "\n", "lab.yaml");
    double speed = 0.5;
    try {
      Section(config, "grasp").number("speed", speed, Range::above_to(0, 1), "fraction");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error, speed ") + std::to_string(speed);
  };
  EXPECT_EQ(error(".nan"), "lab.yaml:2:10: key 'grasp.speed': must be in (0, 1], got nan");
  EXPECT_EQ(error(".inf"), "lab.yaml:2:10: key 'grasp.speed': must be in (0, 1], got inf");
  EXPECT_EQ(error("0"), "lab.yaml:2:10: key 'grasp.speed': must be in (0, 1], got 0");
  EXPECT_EQ(error("1.5"), "lab.yaml:2:10: key 'grasp.speed': must be in (0, 1], got 1.5");
  EXPECT_EQ(error("1"), "no error, speed 1.000000");
}

// A list must have its length and every element in range; a choice must be one of its options.
TEST(Config, ListsAndChoicesAreChecked) {
  const Config config = Config::parse(
      "rig:\n  target: [0.4, .nan, 0.1]\n  short: [1, 2]\n  kind: spiral\n", "lab.yaml");
  Section rig(config, "rig");
  double target[3] = {0, 0, 0}, pair[3] = {0, 0, 0};
  std::string kind = "paper";
  EXPECT_THROW(rig.numbers("target", target, 3, Range::finite(), "m"), ConfigError);
  EXPECT_THROW(rig.numbers("short", pair, 3, Range::finite(), "m"), ConfigError);
  try {
    rig.choice("kind", kind, {"paper", "circle"}, "motion");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(),
                 "lab.yaml:4:9: key 'rig.kind': must be one of paper, circle, got 'spiral'");
  }
}

// A flag's override wins over the file and its errors name the flag, not the file's line.
TEST(Config, OverridesWinAndNameTheFlag) {
  Config config = Config::parse("grasp:\n  standoff: 0.2\n", "lab.yaml");
  config.set_override("grasp.standoff", YAML::Node("0.3"), "--standoff 0.3");
  double standoff = 0.1;
  Section(config, "grasp").number("standoff", standoff, Range::closed(0, 0.5), "m");
  EXPECT_DOUBLE_EQ(standoff, 0.3);
  config.set_override("grasp.standoff", YAML::Node("0.9"), "--standoff 0.9");
  try {
    Section(config, "grasp").number("standoff", standoff, Range::closed(0, 0.5), "m");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "--standoff 0.9: key 'grasp.standoff': must be in [0, 0.5], got 0.9");
  }
}

// A reader run on an empty Config lists its keys with the struct's defaults and requirements.
TEST(Config, DeclaredKeysCarryDefaults) {
  const auto keys = declared_keys([](const Config& c) {
    double standoff = 0.1;
    int order = 12;
    Section s(c, "demo");
    s.number("standoff", standoff, Range::closed(0, 0.5), "m above the ball");
    s.number("order", order, Range::at_least(1), "Burg's order");
  });
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_EQ(keys[0].key, "demo.standoff");
  EXPECT_EQ(keys[0].default_text, "0.1");
  EXPECT_EQ(keys[0].requirement, "must be in [0, 0.5]");
  EXPECT_EQ(keys[1].default_text, "12");
  EXPECT_EQ(keys[1].requirement, "must be at least 1");
}

// The nearest key is the one fewest edits away.
TEST(Config, NearestByEditDistance) {
  EXPECT_EQ(nearest("stanoff", {"lift", "standoff", "speed"}), "standoff");
  EXPECT_EQ(nearest("rate", {"rate_hz", "count"}), "rate_hz");
  EXPECT_EQ(nearest("x", {}), "");
}

}  // namespace
}  // namespace sg
