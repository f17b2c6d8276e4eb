#include "lab/lab_credentials.hpp"

#include <algorithm>
#include <filesystem>

#include "auth/credentials_file.hpp"

namespace sg::lab {

std::string identity_of(const ProcessSpec& p) {
  static const char* kTakeKeys[] = {"sg-camera-sim", "sg-c550-sim",   "sg-vision", "sg-predictor",
                                    "sg-grasp",      "sg-arm-driver", "sg-viewer"};
  if (p.run.empty()) return "";
  const std::string program = std::filesystem::path(p.run.front()).filename().string();
  for (const char* k : kTakeKeys)
    if (program == k) return program;
  return "";
}

bool names_its_key(const ProcessSpec& p) {
  return std::any_of(p.run.begin(), p.run.end(), [](const std::string& a) {
    return a == "--key" || a.rfind("--key=", 0) == 0 || a == "--insecure-no-key";
  });
}

std::string credentials_path(const std::string& session, const std::string& name) {
  return ".sg-lab/credentials/" + session + "/" + name + ".cred";
}

std::map<std::string, std::string> stage_credentials(const LabFile& lab, const auth::LabKey& key,
                                                     const std::string& session,
                                                     const std::string& stage) {
  std::map<std::string, std::string> paths;
  for (const ProcessSpec& p : lab.processes) {
    const std::string identity = identity_of(p);
    if (identity.empty() || names_its_key(p)) continue;
    const std::string path = credentials_path(session, p.name);
    auth::write_credentials_file((std::filesystem::path(stage) / path).string(),
                                 auth::credentials_from_lab_key(key, identity, lab.rights),
                                 "lab '" + lab.lab + "', session " + session + ", process '" +
                                     p.name + "' on " + p.host + ": " + identity);
    paths[p.name] = path;
  }
  return paths;
}

}  // namespace sg::lab
