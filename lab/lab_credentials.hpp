#pragma once

/// The credentials `sg-lab up` makes for a lab's processes (docs/security.md, "Keys in a lab"):
/// from the lab key on the operator's machine, one file per process holding only what that
/// process's identity needs (auth::credentials_from_lab_key), copied to the process's host at
/// `.sg-lab/credentials/<session>/<process>.cred` (mode 0600) and given to it as --key. So a host
/// never holds the lab key, only the keys of the processes it runs: a thief of the cameras' host
/// can speak as sg-camera-sim and sg-vision and as nobody else, and cannot sign a command.
///
///     const auto files = sg::lab::stage_credentials(lab, key, session, stage);   // process ->
///     path shell->copy_all(stage, {files.at("vision")}, 30);                          // to its
///     host

#include <map>
#include <string>

#include "auth/lab_key.hpp"
#include "lab/lab_file.hpp"

namespace sg::lab {

/// The identity process `p` vouches as: its program's name, for the programs that take --key
/// (sg-camera-sim, sg-c550-sim, sg-vision, sg-predictor, sg-grasp, sg-arm-driver, sg-viewer);
/// "" for the others (lcm-logger, a script).
std::string identity_of(const ProcessSpec& p);

/// True when `p`'s own arguments already say which key to use (--key or --insecure-no-key).
bool names_its_key(const ProcessSpec& p);

/// Where process `name`'s credentials go on its host, relative to the project there.
std::string credentials_path(const std::string& session, const std::string& name);

/// Writes the credentials of every process that takes --key (and does not name its own) under
/// `stage`, at credentials_path(); returns process name -> that path.
std::map<std::string, std::string> stage_credentials(const LabFile& lab, const auth::LabKey& key,
                                                     const std::string& session,
                                                     const std::string& stage);

}  // namespace sg::lab
