#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "common/config.hpp"

namespace sg {

/// The options every stereograsp program takes (DESIGN rule 4).
struct CommonOptions {
  std::string lcm_url;             ///< --lcm-url; "" means LCM's default (honours LCM_DEFAULT_URL)
  std::string config_path;         ///< --config FILE; "" means built-in defaults only
  std::string log_level = "info";  ///< --log-level
};

/// Adds --lcm-url, --config and --log-level to `app`, and makes flag errors one line.
void add_common_options(CLI::App& app, CommonOptions& options);

/// Loads --config (or an empty configuration when none was given), sets up logging from
/// --log-level, and settles the bus URL: --lcm-url, else the config's `bus.url`, else LCM's
/// default. Throws ConfigError for a bad file.
Config load_common(CommonOptions& options);

/// Sets spdlog's default logger: stderr, one line a record, prefixed with the program's name.
void init_logging(const std::string& program, const std::string& level);

/// Runs a program's body with the errors every program shares turned into one line on stderr,
/// `<program>: error: <what>`, and exit code 1 (flag errors: one line too, with CLI11's non-zero
/// code).
///
///     int main(int argc, char** argv) {
///       CLI::App app{"What it does", "sg-thing"};
///       sg::CommonOptions common;
///       sg::add_common_options(app, common);
///       return sg::run_program(app, argc, argv, [&] { ...; return 0; });
///     }
int run_program(CLI::App& app, int argc, char** argv, const std::function<int()>& body);

}  // namespace sg
