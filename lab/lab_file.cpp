#include "lab/lab_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "auth/credentials_file.hpp"
#include "common/config.hpp"

namespace sg::lab {
namespace {

/// Reads one YAML mapping, key by key, with errors that name the file, the line and the column;
/// done() refuses every key that was not read, naming the nearest known one.
class Reader {
 public:
  Reader(const YAML::Node& node, std::string file, std::string what)
      : node_(node), file_(std::move(file)), what_(std::move(what)) {
    if (!node_.IsMap()) throw error(node_, what_ + ": expected a mapping of keys");
  }

  LabError error(const YAML::Node& at, const std::string& message) const {
    const YAML::Mark m = at.Mark();
    std::ostringstream where;  // (GCC 12 warns falsely on the string concatenation)
    where << file_;
    if (m.line >= 0) where << ':' << m.line + 1 << ':' << m.column + 1;
    where << ": " << message;
    return LabError(where.str());
  }
  LabError error(const std::string& message) const { return error(node_, message); }

  /// The node under `key`, or an undefined node; remembers the key as known.
  YAML::Node get(const std::string& key) {
    known_.push_back(key);
    return node_[key];
  }

  void text(const std::string& key, std::string& value) {
    const YAML::Node n = get(key);
    if (!n) return;
    if (!n.IsScalar()) throw error(n, what_ + ": '" + key + "' must be text");
    value = n.as<std::string>();
    if (value.find('\0') != std::string::npos || value.find('\n') != std::string::npos)
      throw error(n, what_ + ": '" + key + "' must be one line of text");
  }

  void number(const std::string& key, double& value, double lo, double hi) {
    const YAML::Node n = get(key);
    if (!n) return;
    double v = NAN;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      throw error(n, what_ + ": '" + key + "' must be a number, got '" + scalar(n) + "'");
    }
    if (!(v >= lo && v <= hi))
      throw error(n, what_ + ": '" + key + "' must be in [" + show(lo) + ", " + show(hi) +
                         "], got '" + scalar(n) + "'");
    value = v;
  }

  void list(const std::string& key, std::vector<std::string>& values) {
    const YAML::Node n = get(key);
    if (!n) return;
    if (!n.IsSequence()) throw error(n, what_ + ": '" + key + "' must be a list");
    values.clear();
    for (const YAML::Node& item : n) {
      if (!item.IsScalar()) throw error(item, what_ + ": '" + key + "' must hold text items");
      values.push_back(item.as<std::string>());
    }
  }

  void done() const {
    for (const auto& entry : node_) {
      const std::string key = entry.first.as<std::string>();
      if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
      throw error(entry.first, what_ + ": unknown key '" + key + "' (did you mean '" +
                                   nearest(key, known_) + "'?)");
    }
  }

  static std::string scalar(const YAML::Node& n) {
    return n.IsScalar() ? n.Scalar() : "(not text)";
  }

 private:
  YAML::Node node_;
  std::string file_, what_;
  std::vector<std::string> known_;
};

/// A name sg-lab can use in file names and messages: letters, digits, '-', '_', '.'.
bool plain_name(const std::string& s) {
  return !s.empty() && s.size() <= 64 && s[0] != '.' && s[0] != '-' &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) {
           return std::isalnum(c) || c == '-' || c == '_' || c == '.';
         });
}

/// `env: {NAME: value}`: a mapping of environment variables, each name a shell variable's.
void read_env(Reader& r, const std::string& what, std::map<std::string, std::string>& env) {
  const YAML::Node node = r.get("env");
  if (!node) return;
  if (!node.IsMap()) throw r.error(node, what + ": 'env' must be a mapping");
  static const std::regex kName("[A-Za-z_][A-Za-z0-9_]*");
  for (const auto& e : node) {
    const std::string name = e.first.as<std::string>();
    if (!std::regex_match(name, kName))
      throw r.error(e.first, what + ": 'env' names a variable '" + name +
                                 "' (letters, digits and _, not starting with a digit)");
    env[name] = e.second.as<std::string>();
  }
}

HostSpec read_host(const YAML::Node& node, const std::string& file) {
  HostSpec h;
  Reader r(node, file, "host");
  r.text("name", h.name);
  if (!plain_name(h.name))
    throw r.error("host: 'name' must be a plain name (letters, digits, - _ .), got '" + h.name +
                  "'");
  Reader named(node, file, "host '" + h.name + "'");
  named.get("name");
  named.text("hostname", h.hostname);
  h.hostname_given = !h.hostname.empty();
  if (!h.hostname_given) h.hostname = h.name;
  named.text("address", h.address);
  named.text("user", h.user);
  double port = h.port;
  named.number("port", port, 1, 65535);
  h.port = static_cast<int>(port);
  named.text("path", h.path);
  named.list("ssh_options", h.ssh_options);
  read_env(named, "host '" + h.name + "'", h.env);
  named.done();
  return h;
}

template <class E>
E choice(Reader& r, const std::string& what, const std::string& key, E value,
         const std::vector<std::pair<std::string, E>>& options) {
  std::string text;
  r.text(key, text);
  if (text.empty()) return value;
  std::vector<std::string> names;
  for (const auto& [name, v] : options) {
    if (name == text) return v;
    names.push_back(name);
  }
  std::string all;
  for (const auto& n : names) all += (all.empty() ? "" : ", ") + n;
  throw r.error(r.get(key),
                what + ": '" + key + "' must be one of " + all + ", got '" + text + "'");
}

ProcessSpec read_process(const YAML::Node& node, const std::string& file) {
  ProcessSpec p;
  p.line = node.Mark().line + 1;
  Reader r(node, file, "process");
  r.text("name", p.name);
  if (!plain_name(p.name))
    throw r.error("process: 'name' must be a plain name (letters, digits, - _ .), got '" + p.name +
                  "'");
  const std::string what = "process '" + p.name + "'";
  Reader named(node, file, what);
  named.get("name");
  named.text("host", p.host);
  named.list("run", p.run);
  if (p.run.empty() || p.run[0].empty())
    throw named.error(what + ": 'run' must give the program and its arguments, e.g. [sg-vision]");
  named.list("files", p.files);
  read_env(named, what, p.env);
  p.ready = choice(named, what, "ready", p.stereograsp() ? Readiness::kStatus : Readiness::kStarted,
                   {{"status", Readiness::kStatus}, {"started", Readiness::kStarted}});
  p.restart = choice(named, what, "restart", RestartPolicy::kOnFailure,
                     {{"on-failure", RestartPolicy::kOnFailure},
                      {"always", RestartPolicy::kAlways},
                      {"never", RestartPolicy::kNever}});
  named.done();
  return p;
}

/// Every process on a known host, every name once.
void check_names(const LabFile& lab, const YAML::Node& root, const std::string& file) {
  Reader r(root, file, "lab");
  std::set<std::string> hosts;
  std::string all_hosts;
  for (const HostSpec& h : lab.hosts) {
    if (!hosts.insert(h.name).second)
      throw r.error(root["hosts"], "host '" + h.name + "' is defined twice");
    all_hosts += (all_hosts.empty() ? "" : ", ") + h.name;
  }
  std::set<std::string> names;
  for (size_t i = 0; i < lab.processes.size(); ++i) {
    const ProcessSpec& p = lab.processes[i];
    const YAML::Node node = root["processes"][i];
    if (!names.insert(p.name).second)
      throw r.error(node, "process '" + p.name + "' is defined twice (names must be unique)");
    if (!hosts.count(p.host))
      throw r.error(node, "process '" + p.name + "': host '" + p.host + "' is not in hosts (" +
                              all_hosts + ")");
  }
  if (lab.recorder.enabled && !hosts.count(lab.recorder.host))
    throw r.error(root["recorder"],
                  "recorder: host '" + lab.recorder.host + "' is not in hosts (" + all_hosts + ")");
}

/// One entry of `rights:`: {channel: NAME, publishers: [...], readers: [...]}, over the table.
void read_right(const YAML::Node& node, const std::string& file, auth::ChannelRights& rights) {
  Reader r(node, file, "rights");
  auth::ChannelRight right;
  r.text("channel", right.channel);
  if (!auth::valid_channel_name(right.channel))
    throw r.error(r.get("channel"), "rights: '" + right.channel + "' is not a channel name");
  const std::string what = "rights of " + right.channel;
  Reader named(node, file, what);
  named.get("channel");
  named.list("publishers", right.publishers);
  named.list("readers", right.readers);
  for (const auto* names : {&right.publishers, &right.readers})
    for (const std::string& n : *names)
      if (!valid_vouch_name(n))
        throw named.error(what + ": '" + n + "' is not a program's name (sg-vision, ...)");
  if (right.readers.size() > kVouchMaxTags) throw named.error(what + ": at most 32 readers");
  named.done();
  const auto same = [&](const auth::ChannelRight& x) { return x.channel == right.channel; };
  const auto at = std::find_if(rights.begin(), rights.end(), same);
  if (at != rights.end())
    *at = std::move(right);
  else
    rights.push_back(std::move(right));
}

void read_recorder(Reader& top, LabFile& lab, const std::string& file) {
  const YAML::Node node = top.get("recorder");
  for (const HostSpec& h : lab.hosts)
    if (lab.recorder.host.empty() && h.local()) lab.recorder.host = h.name;
  if (lab.recorder.host.empty() && !lab.hosts.empty()) lab.recorder.host = lab.hosts[0].name;
  if (!node) return;
  if (node.IsScalar() && (node.Scalar() == "off" || node.Scalar() == "false")) {
    lab.recorder.enabled = false;
    return;
  }
  Reader r(node, file, "recorder");
  r.text("host", lab.recorder.host);
  r.text("exclude", lab.recorder.exclude);
  std::string enabled = "true";
  r.text("enabled", enabled);
  if (enabled != "true" && enabled != "false")
    throw r.error(r.get("enabled"), "recorder: 'enabled' must be true or false");
  lab.recorder.enabled = enabled == "true";
  r.done();
}

}  // namespace

/// parse_lab_file's body; yaml-cpp's own exceptions pass through it.
LabFile parse_yaml(const std::string& text, const std::string& name);

bool HostSpec::local() const {
  return address.empty() || address == "localhost" || address == "127.0.0.1" || address == "::1";
}

std::string HostSpec::destination() const { return user.empty() ? address : user + "@" + address; }

std::string ProcessSpec::program() const {
  const std::string& p = run.at(0);
  const size_t slash = p.rfind('/');
  return slash == std::string::npos ? p : p.substr(slash + 1);
}

bool ProcessSpec::stereograsp() const { return program().rfind("sg-", 0) == 0; }

const HostSpec& LabFile::host(const std::string& name) const {
  for (const HostSpec& h : hosts)
    if (h.name == name) return h;
  throw LabError(path + ": no host '" + name + "'");
}

const ProcessSpec* LabFile::process(const std::string& name) const {
  for (const ProcessSpec& p : processes)
    if (p.name == name) return &p;
  return nullptr;
}

LabFile parse_lab_file(const std::string& text, const std::string& name) {
  try {
    return parse_yaml(text, name);
  } catch (const YAML::Exception& e) {  // not YAML, or a value of a kind no key takes
    std::ostringstream where;
    where << name;
    if (e.mark.line >= 0) where << ':' << e.mark.line + 1 << ':' << e.mark.column + 1;
    where << ": " << (dynamic_cast<const YAML::ParserException*>(&e) ? "not YAML: " : "") << e.msg;
    throw LabError(where.str());
  }
}

LabFile parse_yaml(const std::string& text, const std::string& name) {
  const YAML::Node root = YAML::Load(text);
  LabFile lab;
  lab.path = name;
  Reader top(root, name, "lab file");
  top.text("lab", lab.lab);
  if (!plain_name(lab.lab)) throw top.error(top.get("lab"), "'lab' must be a plain name");
  top.text("bus", lab.bus);
  top.text("config", lab.config);
  const YAML::Node hosts = top.get("hosts");
  if (!hosts || !hosts.IsSequence() || hosts.size() == 0)
    throw top.error("'hosts' must list at least one host");
  for (const YAML::Node& h : hosts) lab.hosts.push_back(read_host(h, name));
  const YAML::Node processes = top.get("processes");
  if (!processes || !processes.IsSequence() || processes.size() == 0)
    throw top.error("'processes' must list at least one process");
  for (const YAML::Node& p : processes) lab.processes.push_back(read_process(p, name));
  read_recorder(top, lab, name);
  if (const YAML::Node rights = top.get("rights")) {
    if (!rights.IsSequence()) throw top.error(rights, "'rights' must list channels");
    for (const YAML::Node& r : rights) read_right(r, name, lab.rights);
  }
  if (const YAML::Node t = top.get("timeouts")) {
    Reader r(t, name, "timeouts");
    r.number("ready", lab.ready_timeout, 0.5, 600);
    r.number("stop", lab.stop_timeout, 0.1, 600);
    r.done();
  }
  top.done();
  check_names(lab, root, name);
  return lab;
}

LabFile load_lab_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw LabError(path + ": cannot read the lab file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_lab_file(text.str(), path);
}

const char* to_string(Readiness r) { return r == Readiness::kStatus ? "status" : "started"; }

const char* to_string(RestartPolicy r) {
  switch (r) {
    case RestartPolicy::kOnFailure:
      return "on-failure";
    case RestartPolicy::kAlways:
      return "always";
    case RestartPolicy::kNever:
      return "never";
  }
  return "?";
}

}  // namespace sg::lab
