#include "common/program.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "common/bus.hpp"

namespace sg {

std::string instance_name(const std::string& program) {
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0 || host[0] == '\0')
    std::snprintf(host, sizeof host, "unknown");
  return program + "@" + host + ":" + std::to_string(getpid());
}

void add_common_options(CLI::App& app, CommonOptions& options) {
  app.add_option("--lcm-url", options.lcm_url,
                 "LCM URL, e.g. udpm://239.255.76.67:7667?ttl=1 (default: LCM_DEFAULT_URL, "
                 "else LCM's own default)");
  app.add_option("--config", options.config_path, "YAML configuration file");
  app.add_option("--log-level", options.log_level, "trace, debug, info, warn, error or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.fallthrough();  // common options are accepted after a subcommand too
  const std::string name = app.get_name();
  app.failure_message([name](const CLI::App*, const CLI::Error& e) {
    return name + ": error: " + e.what() + " (see --help)\n";
  });
}

void init_logging(const std::string& program, const std::string& level) {
  auto logger = spdlog::stderr_color_mt(program);
  logger->set_pattern("%Y-%m-%d %H:%M:%S.%e %n %^%l%$: %v");
  logger->set_level(spdlog::level::from_str(level));
  spdlog::set_default_logger(logger);
}

const std::vector<std::string>& config_sections() {
  static const std::vector<std::string> sections = {
      "bus",    "bus_check", "rig", "scenario",   "occlusion", "lighting", "camera_sim",
      "vision", "predictor", "arm", "arm_driver", "c550_sim",  "grasp",    "calibrate_robot"};
  return sections;
}

CLI::Option* ConfigFlags::add(CLI::App& app, const std::string& flag, const std::string& key,
                              const std::vector<KeyInfo>& keys) {
  const auto info =
      std::find_if(keys.begin(), keys.end(), [&](const KeyInfo& k) { return k.key == key; });
  if (info == keys.end()) throw std::logic_error(flag + ": no reader declares key '" + key + "'");
  Bound& b = bound_.emplace_back(Bound{flag, key, {}, false, nullptr});
  std::string help = info->help + " (config " + key;
  if (!info->requirement.empty()) help += "; " + info->requirement;
  b.option = app.add_option(flag, b.values, help + ")")
                 ->expected(info->arity)
                 ->type_name(info->arity > 1 ? "LIST" : "VALUE")
                 ->default_str(info->default_text);
  return b.option;
}

CLI::Option* ConfigFlags::add_switch(CLI::App& app, const std::string& flag, const std::string& key,
                                     const std::string& value, const std::string& help) {
  Bound& b = bound_.emplace_back(Bound{flag, key, {value}, true, nullptr});
  const std::string description = help + " (config " + key + ": " + value + ")";
  b.option = app.add_flag(flag, description);
  return b.option;
}

void ConfigFlags::apply(Config& config) const {
  for (const Bound& b : bound_) {
    if (b.option->count() == 0) continue;
    std::string origin = b.flag;
    YAML::Node value;
    if (b.values.size() == 1) {
      value = YAML::Node(b.values[0]);
      if (!b.is_switch) origin += " " + b.values[0];
    } else {
      for (const std::string& v : b.values) value.push_back(v), origin += " " + v;
    }
    config.set_override(b.key, value, origin);
  }
}

Config load_common(CommonOptions& options) {
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  Config config = options.config_path.empty() ? Config() : Config::load(options.config_path);
  config.reject_unknown_sections(config_sections());
  std::string url;
  Section bus(config, "bus");
  bus.text("url", url, "LCM URL for every process (\"\": LCM's default or LCM_DEFAULT_URL)");
  bus.done();
  if (options.lcm_url.empty()) options.lcm_url = url;
  options.flags.apply(config);
  return config;
}

int run_program(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  const std::string name = app.get_name();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (!spdlog::get(name)) init_logging(name, "info");
    return body();
  } catch (const std::exception& e) {
    std::string what = e.what();  // one line, whatever a library put in its message
    while (!what.empty() && (what.back() == '\n' || what.back() == ' ')) what.pop_back();
    for (char& c : what) c = (c == '\n' || c == '\r') ? ' ' : c;
    std::fprintf(stderr, "%s: error: %s\n", name.c_str(), what.c_str());
    return 1;
  }
}

}  // namespace sg
