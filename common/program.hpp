#pragma once

#include <CLI/CLI.hpp>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "common/config.hpp"

namespace sg {

/// Every section a stereograsp configuration may hold (config/stereograsp.yaml has one per
/// process, plus `arm` and `bus`). load_common() refuses any other section, so a misspelt
/// section name fails in every program; each section's keys are checked by its reader (a
/// `Section`), in the programs that read it. **Add a new section here.**
const std::vector<std::string>& config_sections();

/// Command-line flags that stand for configuration keys. A flag that is given overrides its key
/// (a flag wins over the file, the file over the built-in default), and its value is read and
/// range-checked by the same reader as the file's, so an error names the flag:
/// `--standoff 0.9: key 'grasp.standoff': must be in [0, 0.5], got 0.9`.
class ConfigFlags {
 public:
  /// Adds `flag` for `key` to `app`; its help, requirement and `[default]` come from `keys`
  /// (what the key's reader declares: `declared_keys(read_grasp_settings)`).
  CLI::Option* add(CLI::App& app, const std::string& flag, const std::string& key,
                   const std::vector<KeyInfo>& keys);
  /// A flag without a value that sets `key` to `value` (`--no-prediction`:
  /// grasp.use_prediction false).
  CLI::Option* add_switch(CLI::App& app, const std::string& flag, const std::string& key,
                          const std::string& value, const std::string& help);
  /// Writes the flags given into `config` as overrides.
  void apply(Config& config) const;

 private:
  struct Bound {
    std::string flag, key;
    std::vector<std::string> values;  // as typed; for a switch, its one value
    bool is_switch = false;
    CLI::Option* option = nullptr;
  };
  std::deque<Bound> bound_;  // CLI11 keeps pointers into the entries
};

/// The options every stereograsp program takes (DESIGN rule 4).
struct CommonOptions {
  std::string lcm_url;             ///< --lcm-url; "" means LCM's default (honours LCM_DEFAULT_URL)
  std::string config_path;         ///< --config FILE; "" means built-in defaults only
  std::string log_level = "info";  ///< --log-level
  ConfigFlags flags;               ///< the program's flags that stand for config keys
};

/// Adds --lcm-url, --config and --log-level to `app`, and makes flag errors one line.
void add_common_options(CLI::App& app, CommonOptions& options);

/// Loads --config (or an empty configuration when none was given), refuses unknown sections
/// (config_sections()) and unknown `bus` keys, applies the program's ConfigFlags as overrides,
/// sets up logging from --log-level, and settles the bus URL: --lcm-url, else the config's
/// `bus.url`, else LCM's default. Throws ConfigError for a bad file.
Config load_common(CommonOptions& options);

/// "<program>@<host>:<pid>": this process among all on the bus, e.g. the sender of its commands
/// (two sg-grasp, or a restarted one, are different commanders to sg-arm-driver's lease).
std::string instance_name(const std::string& program);

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
