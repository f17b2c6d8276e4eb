#pragma once

/// What a program holds of the lab's secrets: its credentials (auth/credentials_file.hpp), which
/// guard its bus (every datum vouched for) and, for a program that sends or obeys commands, a
/// signer for what it sends and a verifier for what it receives — or, with `--insecure-no-key`,
/// nothing: it vouches for nothing, sends unsigned and believes everything, after a loud warning.
/// Every program takes the same two flags (`--key PATH`: the lab key, or the credentials sg-lab
/// made for it; default $SG_LAB_KEY else ~/.config/stereograsp/lab.key; and `--insecure-no-key`),
/// and without a usable key and without the flag it exits 2 with one line that says how to make
/// one.
///
///     sg::auth::KeyOptions key_options;
///     sg::auth::add_key_options(app, key_options);
///     return sg::run_program(app, argc, argv, [&] {
///       const sg::Config config = sg::load_common(common);       // logging is set up
///       return sg::auth::with_lab_access(app.get_name(), key_options, [&](auto& lab) {
///         sg::Bus bus(common.lcm_url);
///         lab.guard(bus);                                          // every datum vouched for
///         lab.sign("ARM_COMMAND", command);                        // a sender
///         const std::string why = lab.refusal("ARM_COMMAND", command, sg::now_utime());
///         return 0;                                                // why: "" when accepted
///       });
///     });

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "auth/command_auth.hpp"
#include "auth/credentials_file.hpp"
#include "auth/data_auth.hpp"
#include "auth/lab_key.hpp"
#include "common/bus.hpp"

namespace sg::auth {

/// The exit code of a program started without a usable key and without --insecure-no-key.
constexpr int kExitNoKey = 2;

/// --key and --insecure-no-key.
struct KeyOptions {
  std::string path;       ///< --key; "" means default_key_path()
  bool insecure = false;  ///< --insecure-no-key
};

/// Adds --key PATH and --insecure-no-key (which exclude each other) to `app` or a subcommand.
void add_key_options(CLI::App& app, KeyOptions& options);

/// The signer and verifier of one program, or neither (insecure).
class LabAccess {
 public:
  /// With credentials: signs as `sender` and verifies with `settings` under their command key.
  /// Without: signs nothing (only sets the sender) and accepts every command.
  LabAccess(std::optional<Credentials> credentials, std::string sender,
            VerifierSettings settings = {});

  bool secure() const { return credentials_.has_value(); }
  /// The key commands are signed and checked with (none when insecure, or when the credentials
  /// are of a process that neither sends nor obeys commands).
  const std::optional<LabKey>& command_key() const;
  /// The name this program vouches as: its sender up to the '@' ("sg-grasp").
  std::string identity() const { return sender_.substr(0, sender_.find('@')); }

  /// Makes `bus` vouch for everything it sends and believe only what the lab allows on each
  /// channel (a DataGuard with this program's credentials under the lab key, docs/security.md).
  /// Nothing when insecure, and nothing on a `file://` bus: a recorded log is believed as it was
  /// recorded (its counters are old). Returns the guard, or nullptr. Call before subscribing.
  std::shared_ptr<DataGuard> guard(Bus& bus) const;

  /// The verifier (nullptr when insecure), for its counts.
  const CommandVerifier* verifier() const { return verifier_ ? &*verifier_ : nullptr; }

  /// Signs `command` for `channel` (insecure: sets its sender only). Throws std::runtime_error
  /// when the credentials hold no command key.
  template <class M>
  void sign(const std::string& channel, M& command) {
    if (signer_) {
      signer_->sign(channel, command);
    } else if (secure()) {
      throw std::runtime_error("the credentials of " + identity() +
                               " hold no command key: it may not send commands");
    } else {
      command.sender = sender_;
    }
  }

  /// "" when `command` may be obeyed (always when insecure), else "unauthenticated: <why>".
  template <class M>
  std::string refusal(const std::string& channel, const M& command, int64_t now_utime) {
    if (!verifier_)
      return secure() ? "unauthenticated: " + identity() + " holds no command key" : "";
    const Verification v = verifier_->verify(channel, command, now_utime);
    return v.accepted() ? "" : "unauthenticated: " + v.reason;
  }

 private:
  std::optional<Credentials> credentials_;
  std::string sender_;
  std::optional<CommandSigner> signer_;
  std::optional<CommandVerifier> verifier_;
};

/// For a program that only looks (sg-viewer, the `status` commands): guards `bus` as `program`
/// when the key `options` name (else the default one) can be loaded, else leaves it believing
/// everything and says so in one warning. Never fails for want of a key; nothing on a file://
/// bus. --insecure-no-key: no guard, no warning.
std::shared_ptr<DataGuard> guard_if_key(Bus& bus, const std::string& program,
                                        const KeyOptions& options);

/// Loads the key that `options` name and runs `body` with the program's LabAccess, signing as
/// `program`. With --insecure-no-key, first logs the warning (spdlog warn) "INSECURE: ...". A
/// key that cannot be loaded: "<program>: error: lab key PATH: <why>; make one with ..." on
/// stderr and kExitNoKey. Other exceptions pass through (run_program reports them).
int with_lab_access(const std::string& program, const KeyOptions& options,
                    const std::function<int(LabAccess&)>& body);

}  // namespace sg::auth
