#pragma once

#include <yaml-cpp/yaml.h>

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

 private:
  Config(YAML::Node root, std::string source);

  /// The node at a dotted key, or an undefined node when any part is absent. Throws when a
  /// part before the last is not a map.
  YAML::Node find(const std::string& key) const;
  std::string where(const YAML::Node& node) const;
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
      throw ConfigError(where(node) + ": key '" + key + "': expected " + type_name<T>() + ", got " +
                        describe(node));
    }
  }

  YAML::Node root_;
  std::string source_;
};

}  // namespace sg
