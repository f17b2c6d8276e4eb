#include "common/config.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace sg {
namespace {

std::vector<std::string> split_key(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream stream(key);
  std::string part;
  while (std::getline(stream, part, '.')) parts.push_back(part);
  return parts;
}

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", v);
  return text;
}

/// Levenshtein distance between a and b.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string suggestion(const std::string& prefix, const std::string& word,
                       const std::vector<std::string>& known) {
  const std::string best = nearest(word, known);
  return best.empty() ? "" : " (did you mean '" + prefix + best + "'?)";
}

}  // namespace

std::string Range::requirement() const {
  const Range any = finite();
  if (min == any.min && max == any.max) return "must be a finite number";
  if (max == any.max) {
    if (min == 0) return min_open ? "must be positive" : "must not be negative";
    return (min_open ? "must be above " : "must be at least ") + number_text(min);
  }
  if (min == any.min) return (max_open ? "must be below " : "must be at most ") + number_text(max);
  return "must be in " + std::string(min_open ? "(" : "[") + number_text(min) + ", " +
         number_text(max) + (max_open ? ")" : "]");
}

std::string nearest(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_distance = std::string::npos;
  for (const std::string& c : candidates) {
    const size_t d = edit_distance(word, c);
    if (d < best_distance) best = c, best_distance = d;
  }
  return best;
}

std::string show(double value) { return number_text(value); }

std::string show(const std::vector<double>& values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + number_text(values[i]);
  return text + "]";
}

Config::Config() : root_(YAML::NodeType::Map), source_("<defaults>") {}

Config::Config(YAML::Node root, std::string source)
    : root_(std::move(root)), source_(std::move(source)) {}

Config Config::load(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw ConfigError(path + ": cannot open configuration file");
  std::stringstream text;
  text << file.rdbuf();
  return parse(text.str(), path);
}

Config Config::parse(const std::string& yaml_text, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(name + ":" + std::to_string(e.mark.line + 1) + ":" +
                      std::to_string(e.mark.column + 1) + ": not valid YAML: " + e.msg);
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);  // an empty file is allowed
  if (!root.IsMap()) throw ConfigError(name + ": the top level must be a map of sections");
  return Config(root, name);
}

YAML::Node Config::find(const std::string& key) const {
  if (const auto it = overrides_.find(key); it != overrides_.end()) return it->second.value;
  YAML::Node current(root_);
  std::string walked;
  for (const std::string& part : split_key(key)) {
    if (current.IsNull()) return YAML::Node(YAML::NodeType::Undefined);  // `grasp:` alone
    if (!current.IsMap()) {
      throw ConfigError(where(current) + ": key '" + walked + "' must be a map to hold '" + key +
                        "'");
    }
    const YAML::Node child = std::as_const(current)[part];
    if (!child) return YAML::Node(YAML::NodeType::Undefined);
    current.reset(child);
    walked += (walked.empty() ? "" : ".") + part;
  }
  return current;
}

ConfigError Config::error_at(const std::string& key, const std::string& what) const {
  const YAML::Node node = find(key);
  return ConfigError((node ? location(key, node) : source_) + ": key '" + key + "': " + what);
}

void Config::set_override(const std::string& key, const YAML::Node& value,
                          const std::string& origin) {
  overrides_[key] = {value, origin};
}

void Config::reject_unknown_sections(const std::vector<std::string>& known) const {
  for (const auto& entry : root_) {
    const std::string name = entry.first.Scalar();
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      throw ConfigError(where(entry.first) + ": unknown section '" + name + "'" +
                        suggestion("", name, known));
    }
  }
}

void Config::reject_unknown_keys(const std::string& section,
                                 const std::vector<std::string>& known) const {
  const YAML::Node node = std::as_const(root_)[section];
  if (!node || node.IsNull()) return;
  if (!node.IsMap()) {
    throw ConfigError(where(node) + ": section '" + section + "' must be a map of keys, got " +
                      describe(node));
  }
  for (const auto& entry : node) {
    const std::string name = entry.first.Scalar();
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      throw ConfigError(where(entry.first) + ": unknown key '" + section + "." + name + "'" +
                        suggestion(section + ".", name, known));
    }
  }
}

void Config::declare(const KeyInfo& info) const {
  for (KeyInfo& k : *declared_) {
    if (k.key != info.key) continue;
    // Named first by known() (for its help text), then read with a range: keep the text, take
    // the kind and the range.
    if (k.kind == KeyKind::kTable && info.kind != KeyKind::kTable) {
      k.kind = info.kind, k.range = info.range, k.options = info.options;
      if (k.requirement.empty()) k.requirement = info.requirement;
    }
    return;
  }
  declared_->push_back(info);
}

std::string Config::location(const std::string& key, const YAML::Node& node) const {
  if (const auto it = overrides_.find(key); it != overrides_.end()) return it->second.origin;
  return where(node);
}

Section::Section(const Config& config, std::string name)
    : config_(config), name_(std::move(name)) {}

void Section::declare(KeyInfo info) {
  keys_.push_back(info.key);
  info.key = name_ + "." + info.key;
  config_.declare(info);
}

void Section::numbers(const std::string& key, double* values, int n, const Range& range,
                      const std::string& help) {
  const std::vector<double> fallback(values, values + n);
  const std::string each = range.requirement().substr(std::string("must be ").size());
  declare({key, show(fallback), "must be " + std::to_string(n) + " numbers, each " + each, help, n,
           KeyKind::kNumbers, range, {}});
  const std::string full = name_ + "." + key;
  if (!config_.has(full)) return;
  const auto v = config_.require<std::vector<double>>(full);
  if (static_cast<int>(v.size()) != n) {
    throw config_.error_at(full, "must be a list of " + std::to_string(n) + " numbers, got " +
                                     std::to_string(v.size()));
  }
  for (int i = 0; i < n; ++i) {
    if (!range.contains(v[static_cast<size_t>(i)])) {
      throw config_.error_at(full, "number " + std::to_string(i + 1) + " " + range.requirement() +
                                       ", got " + show(v[i]));
    }
  }
  std::copy(v.begin(), v.end(), values);
}

void Section::text(const std::string& key, std::string& value, const std::string& help) {
  declare({key, value.empty() ? "\"\"" : value, "", help, 1, KeyKind::kText, {}, {}});
  value = config_.get<std::string>(name_ + "." + key, value);
}

void Section::choice(const std::string& key, std::string& value,
                     const std::vector<std::string>& options, const std::string& help) {
  std::string list;
  for (const std::string& o : options) list += (list.empty() ? "" : ", ") + o;
  declare({key, value, "must be one of " + list, help, 1, KeyKind::kChoice, {}, options});
  const std::string full = name_ + "." + key;
  const std::string v = config_.get<std::string>(full, value);
  if (std::find(options.begin(), options.end(), v) == options.end())
    throw config_.error_at(full, "must be one of " + list + ", got '" + v + "'");
  value = v;
}

void Section::flag(const std::string& key, bool& value, const std::string& help) {
  declare({key, value ? "true" : "false", "", help, 1, KeyKind::kFlag, {}, {}});
  value = config_.get<bool>(name_ + "." + key, value);
}

std::string Config::where(const YAML::Node& node) const {
  const YAML::Mark mark = node.Mark();
  if (mark.is_null()) return source_;
  return source_ + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

std::string Config::describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar:
      return "'" + node.Scalar() + "'";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Null:
      return "nothing";
    default:
      return "an undefined value";
  }
}

}  // namespace sg
