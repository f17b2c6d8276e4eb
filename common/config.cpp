#include "common/config.hpp"

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

}  // namespace

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
  YAML::Node current(root_);
  std::string walked;
  for (const std::string& part : split_key(key)) {
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
  return ConfigError((node ? where(node) : source_) + ": key '" + key + "': " + what);
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
