#include "common/program.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "common/bus.hpp"

namespace sg {

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

Config load_common(CommonOptions& options) {
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  Config config = options.config_path.empty() ? Config() : Config::load(options.config_path);
  if (options.lcm_url.empty()) options.lcm_url = config.get<std::string>("bus.url", "");
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
