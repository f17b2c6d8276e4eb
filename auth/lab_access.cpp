#include "auth/lab_access.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>

#include "common/program.hpp"

namespace sg::auth {

void add_key_options(CLI::App& app, KeyOptions& options) {
  CLI::Option* key = app.add_option(
      "--key", options.path,
      "lab key file that signs and checks commands, mode 0600 (default: $SG_LAB_KEY, else "
      "~/.config/stereograsp/lab.key; make one with sg-keygen)");
  CLI::Option* insecure = app.add_flag(
      "--insecure-no-key", options.insecure,
      "run without a lab key: send commands unsigned and accept unsigned ones (anyone on the "
      "network can then command the arm)");
  key->excludes(insecure);
}

LabAccess::LabAccess(std::optional<LabKey> key, std::string sender, VerifierSettings settings)
    : key_(std::move(key)), sender_(std::move(sender)) {
  if (key_) {
    signer_.emplace(*key_, sender_);
    verifier_.emplace(*key_, settings);
  }
}

std::shared_ptr<DataGuard> LabAccess::guard(Bus& bus) const {
  if (!key_) return nullptr;
  if (bus.url().rfind("file://", 0) == 0) {
    spdlog::info("reading a recorded log ({}): its messages are believed as recorded", bus.url());
    return nullptr;
  }
  auto guard = std::make_shared<DataGuard>(credentials_from_lab_key(*key_, identity()));
  bus.set_guard(guard);
  return guard;
}

std::shared_ptr<DataGuard> guard_if_key(Bus& bus, const std::string& program,
                                        const KeyOptions& options) {
  if (options.insecure) return nullptr;
  try {
    const std::string path = options.path.empty() ? default_key_path() : options.path;
    return LabAccess(LabKey::load(path), instance_name(program)).guard(bus);
  } catch (const LabKeyError& e) {
    spdlog::warn("{}; showing what arrives without checking who sent it", e.what());
    return nullptr;
  }
}

int with_lab_access(const std::string& program, const KeyOptions& options,
                    const std::function<int(LabAccess&)>& body) {
  std::optional<LabKey> key;
  if (options.insecure) {
    spdlog::warn(
        "INSECURE: running without a lab key (--insecure-no-key): nothing it sends is signed or "
        "vouched for, and it believes and obeys whatever arrives; anyone on the network can "
        "steer the arm");
  } else {
    std::string path;
    try {
      path = options.path.empty() ? default_key_path() : options.path;
      key = LabKey::load(path);
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
  LabAccess lab(std::move(key), instance_name(program));
  return body(lab);
}

}  // namespace sg::auth
