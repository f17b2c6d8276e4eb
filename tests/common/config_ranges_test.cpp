// Every configuration value has a range: for every key every reader declares (its KeyInfo, so a
// key added later is covered without touching this file), NaN, both infinities and values beyond
// each end of its range are refused with the file, the line, the column and the key; strings
// with a fixed set of values refuse any other; and the flags that stand for keys are refused in
// one line as well.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iomanip>
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

/// Every settings reader of the product (each program runs one or more of them).
const std::vector<Reader>& readers() {
  static const std::vector<Reader> all = {
      [](const Config& c) { bus_check::read_send_settings(c); },
      [](const Config& c) { sim::load_sim_params(c); },
      [](const Config& c) { arm::load_arm_geometry(c); },
      [](const Config& c) { sim::read_c550_sim_settings(c); },
      [](const Config& c) { vision::read_vision_settings(c); },
      [](const Config& c) { vision::load_robot_calibration_params(c); },
      [](const Config& c) { predictor::read_predictor_settings(c); },
      [](const Config& c) { arm::read_arm_driver_settings(c); },
      [](const Config& c) { grasp::read_grasp_settings(c); },
  };
  return all;
}

/// Every key any reader declares, with its kind and range.
std::vector<KeyInfo> all_keys() {
  const Config probe;
  for (const Reader& read : readers()) read(probe);
  return probe.declared_keys();
}

/// Runs every reader on `yaml` (as the file lab.yaml); the error, or "" when all accept it.
std::string error_of(const std::string& yaml) {
  const Config config = Config::parse(yaml, "lab.yaml");
  try {
    for (const Reader& read : readers()) read(config);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

/// The key's section and leaf name.
std::pair<std::string, std::string> split(const std::string& key) {
  const size_t dot = key.find('.');
  return {key.substr(0, dot), key.substr(dot + 1)};
}

/// A one-key file: `section:\n  leaf: value\n`; the value sits on line 2 at column leaf + 5.
std::string one_key(const KeyInfo& k, const std::string& value) {
  const auto [section, leaf] = split(k.key);
  return section + ":\n  " + leaf + ": " + value + "\n";
}

/// What every refusal of key `k` starts with: the file, line 2, the value's column, the key.
std::string prefix_of(const KeyInfo& k) {
  const std::string leaf = split(k.key).second;
  return "lab.yaml:2:" + std::to_string(leaf.size() + 5) + ": key '" + k.key + "': ";
}

/// `v` as YAML: integers without a fraction, reals with 17 digits.
std::string yaml_number(double v, bool integer) {
  std::ostringstream text;
  text.precision(17);
  if (integer) {
    text << std::fixed << std::setprecision(0) << v;
  } else {
    text << v;
  }
  return text.str();
}

/// Values outside `r` on both sides: beyond each finite end by at least 1 and by its size.
std::vector<double> outside(const Range& r, bool integer) {
  const double below = r.min - std::max(1.0, std::abs(r.min));
  const double above = r.max + std::max(1.0, std::abs(r.max));
  std::vector<double> out = {integer ? std::floor(below) : below, integer ? std::ceil(above) : above};
  if (r.min_open) out.push_back(r.min);  // the open end itself
  if (r.max_open) out.push_back(r.max);
  return out;
}

/// True when `word` is a number as YAML reads it.
bool is_number(const std::string& word) {
  try {
    size_t used = 0;
    std::stod(word, &used);
    return used == word.size();
  } catch (const std::exception&) {
    return false;
  }
}

/// The text of a list of `k.arity` numbers: the defaults (0 where the default is not a number,
/// as "pi 0 atan2(y,x)+pi"), with number `i` (0-based) replaced.
std::string list_with(const KeyInfo& k, int i, const std::string& bad) {
  std::vector<std::string> parts;
  std::string cleaned = k.default_text;
  for (char& c : cleaned) c = (c == '[' || c == ']' || c == ',') ? ' ' : c;
  std::istringstream in(cleaned);
  std::string word;
  while (in >> word) parts.push_back(is_number(word) ? word : "0");
  parts.resize(static_cast<size_t>(k.arity), "0");
  parts[static_cast<size_t>(i)] = bad;
  std::string text = "[";
  for (size_t j = 0; j < parts.size(); ++j) text += (j ? ", " : "") + parts[j];
  return text + "]";
}

bool numeric(const KeyInfo& k) {
  return k.kind == KeyKind::kNumber || k.kind == KeyKind::kInteger || k.kind == KeyKind::kNumbers;
}

// The readers cover every section load_common() accepts (a new section needs its reader here).
TEST(ConfigRanges, EverySectionIsCovered) {
  const std::vector<KeyInfo> keys = all_keys();
  for (const std::string& section : config_sections()) {
    if (section == "bus") continue;  // load_common's own: one text key
    const bool covered = std::any_of(keys.begin(), keys.end(), [&](const KeyInfo& k) {
      return k.key.rfind(section + ".", 0) == 0;
    });
    EXPECT_TRUE(covered) << section;
  }
}

// Every numeric key has a range with finite ends: no margin, time, rate, horizon, order or size
// can be absurdly large or small; a key read by hand (kTable) is one of the known tables.
TEST(ConfigRanges, EveryNumberHasABoundedRange) {
  const std::vector<std::string> tables = {"arm.dh", "arm.limits_deg", "occlusion.episodes",
                                           "calibrate_robot.grid"};
  for (const KeyInfo& k : all_keys()) {
    SCOPED_TRACE(k.key);
    if (k.kind == KeyKind::kTable) {
      EXPECT_NE(std::find(tables.begin(), tables.end(), k.key), tables.end())
          << "read by hand: give it a range (Section::number, numbers) or test it as a table";
      continue;
    }
    if (!numeric(k)) continue;
    EXPECT_GT(k.range.min, -Range::finite().max) << k.requirement;
    EXPECT_LT(k.range.max, Range::finite().max) << k.requirement;
    EXPECT_FALSE(k.requirement.empty());
  }
}

// NaN, +inf and -inf are refused for every numeric key (each number of a list), naming the key.
TEST(ConfigRanges, NonFiniteValuesAreRefusedForEveryKey) {
  for (const KeyInfo& k : all_keys()) {
    if (!numeric(k)) continue;
    for (const std::string bad : {".nan", ".inf", "-.inf"}) {
      const int n = k.kind == KeyKind::kNumbers ? k.arity : 1;
      for (int i = 0; i < n; ++i) {
        const std::string value = k.kind == KeyKind::kNumbers ? list_with(k, i, bad) : bad;
        const std::string error = error_of(one_key(k, value));
        EXPECT_EQ(error.rfind(prefix_of(k), 0), 0u) << k.key << ": " << value << " -> " << error;
      }
    }
  }
}

// A value beyond either end of a key's range (and an open end itself) is refused, naming the key
// and its range; a list refuses one bad number among good ones, saying which.
TEST(ConfigRanges, OutOfRangeValuesAreRefusedForEveryKey) {
  int checked = 0;
  for (const KeyInfo& k : all_keys()) {
    if (!numeric(k)) continue;
    for (const double v : outside(k.range, k.kind == KeyKind::kInteger)) {
      const std::string bad = yaml_number(v, k.kind == KeyKind::kInteger);
      const std::string value = k.kind == KeyKind::kNumbers ? list_with(k, k.arity - 1, bad) : bad;
      const std::string error = error_of(one_key(k, value));
      EXPECT_EQ(error.rfind(prefix_of(k), 0), 0u) << k.key << ": " << value << " -> " << error;
      if (k.kind == KeyKind::kNumbers) {
        EXPECT_NE(error.find("number " + std::to_string(k.arity)), std::string::npos) << error;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);  // every section's keys, not a few
}

// The default of every numeric key lies in its own range (so the refusals above are the range's
// doing, not a bad default).
TEST(ConfigRanges, EveryDefaultIsInItsRange) {
  for (const KeyInfo& k : all_keys()) {
    if (k.kind != KeyKind::kNumber && k.kind != KeyKind::kInteger) continue;
    if (k.default_text == "nan") continue;  // "unset" (scenario.phase_deg: drawn from the seed)
    EXPECT_TRUE(k.range.contains(std::stod(k.default_text))) << k.key << " = " << k.default_text;
    EXPECT_EQ(error_of(one_key(k, k.default_text)), "") << k.key;
  }
}

// A key with a fixed set of values refuses any other, listing them; true/false keys refuse text.
TEST(ConfigRanges, ChoicesAndFlagsRefuseOtherValues) {
  int choices = 0;
  for (const KeyInfo& k : all_keys()) {
    if (k.kind == KeyKind::kChoice) {
      ASSERT_FALSE(k.options.empty()) << k.key;
      const std::string error = error_of(one_key(k, "nonsense"));
      EXPECT_EQ(error.rfind(prefix_of(k) + "must be one of ", 0), 0u) << error;
      EXPECT_NE(error.find(k.options.front()), std::string::npos) << error;
      ++choices;
    } else if (k.kind == KeyKind::kFlag) {
      const std::string error = error_of(one_key(k, "maybe"));
      EXPECT_EQ(error.rfind(prefix_of(k) + "expected true or false", 0), 0u) << error;
    }
  }
  EXPECT_GE(choices, 3);  // predictor.model, scenario.kind, camera_sim.encoding at least
  // A text whose form is fixed is checked by its reader, naming the key.
  EXPECT_EQ(error_of("arm_driver:\n  framing: 9X3\n").rfind("lab.yaml:2:12: key 'arm_driver.framing': ", 0),
            0u);
}

// The measured defect: a NaN (or infinite, or absurd) table_z in sg-grasp's config is refused by
// sg-grasp's own reader, so it can no longer reach the table check.
TEST(ConfigRanges, TableZNaNIsRefusedBySgGraspsReader) {
  for (const std::string bad : {".nan", ".NaN", ".inf", "-.inf", "1e300", "-1e300"}) {
    const Config config = Config::parse("grasp:\n  table_z: " + bad + "\n", "lab.yaml");
    try {
      grasp::read_grasp_settings(config);
      FAIL() << bad << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("lab.yaml:2:12: key 'grasp.table_z': must be in ", 0),
                0u)
          << e.what();
    }
  }
  // Through a flag standing for a key, the same reader names the flag.
  Config config = Config::parse("grasp:\n  table_z: 0.0\n", "lab.yaml");
  config.set_override("grasp.table_margin", YAML::Node(".nan"), "--table-margin .nan");
  try {
    grasp::read_grasp_settings(config);
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--table-margin .nan: key 'grasp.table_margin': ", 0), 0u)
        << e.what();
  }
}

// The tables read by hand refuse a NaN, an infinity and an absurd value in any row.
TEST(ConfigRanges, TablesRefuseNonFiniteAndAbsurdRows) {
  const std::map<std::string, std::vector<std::string>> cases = {
      {"arm:\n  dh: [[0, 0, .nan, 0], [-90, 0, 0, -90], [0, 0.305, 0, -90], [-90, 0, 0.330, 0], "
       "[90, 0, 0, 0], [-90, 0, 0.076, 180]]\n",
       {"lab.yaml:2:7: key 'arm.dh': "}},
      {"arm:\n  limits_deg: [[-175, 175], [-90, .inf], [-110, 110], [-180, 180], [-105, 105], "
       "[-180, 180]]\n",
       {"lab.yaml:2:15: key 'arm.limits_deg': "}},
      {"arm:\n  limits_deg: [[-175, 175], [-90, 1e9], [-110, 110], [-180, 180], [-105, 105], "
       "[-180, 180]]\n",
       {"lab.yaml:2:15: key 'arm.limits_deg': "}},
      {"occlusion:\n  episodes: [[4.0, .nan]]\n", {"lab.yaml:2:13: key 'occlusion.episodes': "}},
      {"occlusion:\n  episodes: [[-1e300, 2.0]]\n", {"lab.yaml:2:13: key 'occlusion.episodes': "}},
      {"calibrate_robot:\n  grid: [3, 3, 1000000]\n", {"lab.yaml:2:9: key 'calibrate_robot.grid': "}},
  };
  for (const auto& [yaml, prefixes] : cases) {
    const std::string error = error_of(yaml);
    EXPECT_EQ(error.rfind(prefixes.front(), 0), 0u) << yaml << " -> " << error;
  }
}

// A flag that stands for a key is refused in one line naming the flag and the key, non-zero exit
// (run_program's 1, as for every configuration error).
TEST(ConfigRanges, FlagsAreRefusedInOneLine) {
  const std::vector<std::vector<std::string>> cases = {
      {"sg-grasp", "--standoff", ".nan"}, {"sg-grasp", "--speed", ".inf"},
      {"sg-grasp", "--standoff", "nan"},  {"sg-predictor", "--horizon", "100000000"},
      {"sg-predictor", "--order", "-3"},  {"sg-predictor", "--max-time-offset", "-1"},
  };
  for (const auto& args : cases) {
    const test::ProcessResult r =
        test::run({test::program(args[0]), args[1], args[2], "--lcm-url", "memq://"});
    EXPECT_EQ(r.exit_code, 1) << args[1] << " " << args[2] << ": " << r.err;
    EXPECT_EQ(test::count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(args[1] + " " + args[2] + ": key '"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace sg
