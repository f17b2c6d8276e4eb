#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace sg {

/// A configuration problem: the message names the file, the line, the key and what was wrong,
/// e.g. `config/lab.yaml:12:3: key 'bus_check.rate_hz': expected a number, got 'fast'`.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An interval a number must lie in. NaN and the infinities lie in none, so every range refuses
/// them (`!(v >= min)` is true for NaN).
struct Range {
  double min = -std::numeric_limits<double>::max();
  double max = std::numeric_limits<double>::max();
  bool min_open = false, max_open = false;

  static Range finite() { return {}; }
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range at_least(double lo) { return {lo, finite().max, false, false}; }
  static Range above(double lo) { return {lo, finite().max, true, false}; }
  static Range above_to(double lo, double hi) { return {lo, hi, true, false}; }  ///< (lo, hi]

  bool contains(double v) const {
    return std::isfinite(v) && (min_open ? v > min : v >= min) && (max_open ? v < max : v <= max);
  }
  /// "must be in [0, 0.5]", "must be positive", "must not be negative", "must be at least 10".
  std::string requirement() const;
};

/// What kind of value a key holds, as its reader declares it.
enum class KeyKind {
  kNumber,   ///< a real number in `range`
  kInteger,  ///< an integer in `range`
  kNumbers,  ///< a list of `arity` real numbers, each in `range`
  kText,     ///< any string (a path, a URL)
  kChoice,   ///< one of `options`
  kFlag,     ///< true or false
  kTable,    ///< read and checked by the reader itself (a list of rows, say)
};

/// What a settings reader says about one key: for `--help`, for suggestions, and for the tests
/// that drive every key with NaN, infinities and values out of its range
/// (tests/common/config_ranges_test.cpp).
struct KeyInfo {
  std::string key;           ///< dotted: `grasp.standoff`
  std::string default_text;  ///< the settings struct's default, as text
  std::string requirement;   ///< "must be in [0, 0.5]" ("" when any value of its type goes)
  std::string help;          ///< what it means, with its unit
  int arity = 1;             ///< values a flag for it takes (a list of 3: 3)
  KeyKind kind = KeyKind::kTable;
  Range range;                       ///< kNumber, kInteger, kNumbers: the values accepted
  std::vector<std::string> options;  ///< kChoice: the values accepted
};

/// The key nearest to `word` by edit distance (Levenshtein), "" when `candidates` is empty.
std::string nearest(const std::string& word, const std::vector<std::string>& candidates);

/// `value` as short text: 0.1, 38400, true, 'jpeg'-less plain strings, [0.45, 0, 0.1].
std::string show(double value);
std::string show(const std::vector<double>& values);

/// A YAML configuration file (yaml-cpp), read with dotted keys.
///
///     sg::Config config = sg::Config::load("config/stereograsp.yaml");
///     double rate = config.get<double>("bus_check.rate_hz", 100.0);   // default if absent
///     int order = config.require<int>("predictor.order");             // error if absent
///     if (rate <= 0) throw config.error_at("bus_check.rate_hz", "must be positive");
class Config {
 public:
  /// An empty configuration: every get() returns its default.
  Config();

  /// Reads a file; throws ConfigError if it cannot be opened, is not valid YAML, or its top
  /// level is not a map.
  static Config load(const std::string& path);

  /// Parses text (tests, or configuration embedded in a program); `name` stands for the file.
  static Config parse(const std::string& yaml_text, const std::string& name = "<text>");

  /// The value at a dotted key (`section.key`), converted to T, or `fallback` when absent.
  /// Throws ConfigError when present but not convertible.
  template <class T>
  T get(const std::string& key, const T& fallback) const {
    const YAML::Node node = find(key);
    return node ? convert<T>(key, node) : fallback;
  }

  /// The value at a dotted key, converted to T; throws ConfigError when absent or malformed.
  template <class T>
  T require(const std::string& key) const {
    const YAML::Node node = find(key);
    if (!node) throw ConfigError(source_ + ": key '" + key + "' is missing");
    return convert<T>(key, node);
  }

  /// True when the dotted key is present.
  bool has(const std::string& key) const { return static_cast<bool>(find(key)); }

  /// A ConfigError for a value that converts but is not acceptable (out of range, say), naming
  /// the file, the line of the key when present, and the key.
  ConfigError error_at(const std::string& key, const std::string& what) const;

  /// The file name (or the name given to parse()).
  const std::string& source() const { return source_; }

  /// Makes `key` hold `value` whatever the file says (a command-line flag: flags win over the
  /// file). Errors about the key then name `origin` (`--standoff 0.9`) instead of a file line.
  void set_override(const std::string& key, const YAML::Node& value, const std::string& origin);

  /// Throws `file:line:col: unknown section 'gasp' (did you mean 'grasp'?)` for the first
  /// top-level key that is not in `known`.
  void reject_unknown_sections(const std::vector<std::string>& known) const;

  /// Throws `file:line:col: unknown key 'grasp.stanoff' (did you mean 'grasp.standoff'?)` for
  /// the first key of `section` not in `known` (leaf names).
  void reject_unknown_keys(const std::string& section, const std::vector<std::string>& known) const;

  /// Every key a reader has declared while reading this configuration (or a copy of it), in
  /// order: run a reader on an empty Config to list its keys, defaults, ranges and help.
  const std::vector<KeyInfo>& declared_keys() const { return *declared_; }
  void declare(const KeyInfo& info) const;

 private:
  Config(YAML::Node root, std::string source);

  /// The node at a dotted key, or an undefined node when any part is absent. Throws when a
  /// part before the last is not a map.
  YAML::Node find(const std::string& key) const;
  std::string where(const YAML::Node& node) const;
  /// The flag that set `key`, else where `node` is in the file.
  std::string location(const std::string& key, const YAML::Node& node) const;
  static std::string describe(const YAML::Node& node);
  template <class T>
  static constexpr const char* type_name() {
    if constexpr (std::is_same_v<T, bool>)
      return "true or false";
    else if constexpr (std::is_integral_v<T>)
      return "an integer";
    else if constexpr (std::is_floating_point_v<T>)
      return "a number";
    else if constexpr (std::is_same_v<T, std::string>)
      return "a string";
    else
      return "a list or map of the right kind";
  }

  template <class T>
  T convert(const std::string& key, const YAML::Node& node) const {
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      throw ConfigError(location(key, node) + ": key '" + key + "': expected " + type_name<T>() +
                        ", got " + describe(node));
    }
  }

  struct Override {
    YAML::Node value;
    std::string origin;
  };

  YAML::Node root_;
  std::string source_;
  std::map<std::string, Override> overrides_;
  std::shared_ptr<std::vector<KeyInfo>> declared_ = std::make_shared<std::vector<KeyInfo>>();
};

/// One section of a configuration read into a settings struct: each call names a key, its
/// field (which holds the default on entry), its range and its help; `done()` then refuses any
/// key of the section that no call named. A reader is the one place its settings are read and
/// checked:
///
///     GraspSettings read_grasp_settings(const Config& config) {
///       GraspSettings s;
///       Section grasp(config, "grasp");
///       grasp.number("standoff", s.standoff, Range::closed(0, 0.5), "m above the ball");
///       ...
///       grasp.done();
///       return s;
///     }
///
/// Errors name the file, line and key: `lab.yaml:14:13: key 'grasp.standoff': must be in
/// [0, 0.5], got 0.9` (or the flag that set it).
class Section {
 public:
  Section(const Config& config, std::string name);

  /// A number in `range` (NaN refused). T: double, int or int64_t.
  template <class T>
  void number(const std::string& key, T& value, const Range& range, const std::string& help) {
    static_assert(std::is_arithmetic_v<T> && !std::is_same_v<T, bool>);
    declare({key, show(static_cast<double>(value)), range.requirement(), help, 1,
             std::is_integral_v<T> ? KeyKind::kInteger : KeyKind::kNumber, range, {}});
    const std::string full = name_ + "." + key;
    if (!config_.has(full)) return;
    const T v = config_.get<T>(full, value);
    if (!range.contains(static_cast<double>(v))) {
      throw config_.error_at(full, range.requirement() + ", got " + show(static_cast<double>(v)));
    }
    value = v;
  }
  /// A list of exactly `n` numbers, each in `range`, into values[0..n).
  void numbers(const std::string& key, double* values, int n, const Range& range,
               const std::string& help);
  /// Any string.
  void text(const std::string& key, std::string& value, const std::string& help);
  /// One of `options`.
  void choice(const std::string& key, std::string& value, const std::vector<std::string>& options,
              const std::string& help);
  /// true or false.
  void flag(const std::string& key, bool& value, const std::string& help);
  /// Any value of type T, which the caller checks (error()); true when the key is present.
  template <class T>
  bool read(const std::string& key, T& value, const std::string& default_text,
            const std::string& help, int arity = 1) {
    declare({key, default_text, "", help, arity, KeyKind::kTable, {}, {}});
    const std::string full = name_ + "." + key;
    if (!config_.has(full)) return false;
    value = config_.require<T>(full);
    return true;
  }

  /// Names a key the caller reads itself (a table, say); true when it is present.
  bool known(const std::string& key, const std::string& default_text, const std::string& help,
             int arity = 0) {
    declare({key, default_text, "", help, arity, KeyKind::kTable, {}, {}});
    return config_.has(name_ + "." + key);
  }

  /// An error about `key` of this section (a value that converts but does not fit).
  ConfigError error(const std::string& key, const std::string& what) const {
    return config_.error_at(name_ + "." + key, what);
  }
  /// Refuses every key of the section that no call named, suggesting the nearest.
  void done() const { config_.reject_unknown_keys(name_, keys_); }

 private:
  /// Declares `info`, whose `key` is the leaf name (the section's name is prefixed).
  void declare(KeyInfo info);

  const Config& config_;
  std::string name_;
  std::vector<std::string> keys_;
};

/// The keys `read` declares, with their defaults, on an empty configuration.
///
///     const auto keys = sg::declared_keys([](const sg::Config& c) { read_grasp_settings(c); });
template <class Reader>
std::vector<KeyInfo> declared_keys(Reader&& read) {
  const Config probe;
  read(probe);
  return probe.declared_keys();
}

}  // namespace sg
