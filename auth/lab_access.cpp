#include "auth/lab_access.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>

#include "common/program.hpp"

namespace sg::auth {

void add_key_options(CLI::App& app, KeyOptions& options) {
  CLI::Option* key = app.add_option(
      "--key", options.path,
      "the lab key, or the credentials sg-lab made for this process, mode 0600: what vouches for "
      "its messages, checks what it hears and signs its commands (default: $SG_LAB_KEY, else "
      "~/.config/stereograsp/lab.key; make one with sg-keygen)");
  CLI::Option* insecure = app.add_flag(
      "--insecure-no-key", options.insecure,
      "run without a lab key: vouch for nothing, sign nothing, and believe and obey whatever "
      "arrives (anyone on the network can then steer the arm)");
  key->excludes(insecure);
}

LabAccess::LabAccess(std::optional<Credentials> credentials, std::string sender,
                     VerifierSettings settings)
    : credentials_(std::move(credentials)), sender_(std::move(sender)) {
  if (credentials_ && credentials_->command_key) {
    signer_.emplace(*credentials_->command_key, sender_);
    verifier_.emplace(*credentials_->command_key, settings);
  }
}

const std::optional<LabKey>& LabAccess::command_key() const {
  static const std::optional<LabKey> none;
  return credentials_ ? credentials_->command_key : none;
}

std::shared_ptr<DataGuard> LabAccess::guard(Bus& bus) const {
  if (!credentials_) return nullptr;
  if (bus.url().rfind("file://", 0) == 0) {
    spdlog::info("reading a recorded log ({}): its messages are believed as recorded", bus.url());
    return nullptr;
  }
  auto guard = std::make_shared<DataGuard>(*credentials_);
  bus.set_guard(guard);
  return guard;
}

std::shared_ptr<DataGuard> guard_if_key(Bus& bus, const std::string& program,
                                        const KeyOptions& options) {
  if (options.insecure) return nullptr;
  try {
    const std::string path = options.path.empty() ? default_key_path() : options.path;
    return LabAccess(load_key_file(path, program), instance_name(program)).guard(bus);
  } catch (const LabKeyError& e) {
    spdlog::warn("{}; showing what arrives without checking who sent it", e.what());
    return nullptr;
  }
}

int with_lab_access(const std::string& program, const KeyOptions& options,
                    const std::function<int(LabAccess&)>& body) {
  std::optional<Credentials> credentials;
  if (options.insecure) {
    spdlog::warn(
        "INSECURE: running without a lab key (--insecure-no-key): nothing it sends is signed or "
        "vouched for, and it believes and obeys whatever arrives; anyone on the network can "
        "steer the arm");
  } else {
    std::string path;
    try {
      path = options.path.empty() ? default_key_path() : options.path;
      credentials = load_key_file(path, program);
    } catch (const LabKeyError& e) {
      std::error_code ec;
      const bool missing = path.empty() || !std::filesystem::exists(path, ec);
      std::fprintf(stderr, "%s: error: %s; %s\n", program.c_str(), e.what(),
                   missing ? ("make one with `sg-keygen " + path +
                              "` and copy it to every lab machine (mode 0600), give --key PATH, "
                              "or run with --insecure-no-key")
                                 .c_str()
                           : "fix it, give --key PATH, or run with --insecure-no-key");
      return kExitNoKey;
    }
  }
  LabAccess lab(std::move(credentials), instance_name(program));
  return body(lab);
}

}  // namespace sg::auth
