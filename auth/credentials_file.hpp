#pragma once

/// One process's credentials in a file (docs/security.md): what `sg-lab up` makes for each process
/// of a lab from the lab key and copies to its host, so that a host holds the keys of its own
/// processes and no others. Text, mode 0600, at most 64 KiB:
///
///     # comment lines
///     stereograsp-credentials 1
///     identity sg-vision
///     command-key <64 hex>                          (only for processes that send or obey
///     commands) send sg-predictor <64 hex> OBJECT_POSITION    (K(identity -> reader), the channels
///     it covers) receive sg-camera-sim <64 hex> CAMERA_LEFT,CAMERA_RIGHT
///
/// Every program's --key takes either this or the lab key itself (64 hex characters: every pair
/// derived, for a bench on one host), and load_key_file() tells them apart.
///
///     sg::auth::write_credentials_file("creds/vision.cred",
///         sg::auth::credentials_from_lab_key(lab, "sg-vision"), "lab3, process vision");
///     const sg::auth::Credentials c = sg::auth::load_key_file("creds/vision.cred", "sg-vision");

#include <string>

#include "auth/data_auth.hpp"

namespace sg::auth {

inline constexpr std::size_t kMaxCredentialsFile = 64 * 1024;

/// The file's text for `credentials`, with `comment` (one line) at the top.
std::string format_credentials(const Credentials& credentials, const std::string& comment);

/// Parses a credentials file's text; throws LabKeyError "credentials PATH:LINE: why" for anything
/// but the lines above (an unknown word, a bad name, key or channel, a repeated identity or peer,
/// no identity, more than 256 peers).
Credentials parse_credentials(const std::string& text, const std::string& path);

/// Writes `credentials` to `path` (mode 0600, replacing it). Throws LabKeyError.
void write_credentials_file(const std::string& path, const Credentials& credentials,
                            const std::string& comment);

/// What the key file at `path` gives the program `identity`: with the lab key, its credentials
/// derived for every pair (credentials_from_lab_key); with a credentials file, those, which must
/// be `identity`'s. Throws LabKeyError naming the path.
Credentials load_key_file(const std::string& path, const std::string& identity);

/// True when two credentials hold the same identity, keys and channels, peer by peer in order.
bool same_credentials(const Credentials& a, const Credentials& b);

/// True when `name` can be a channel in a credentials file: 1..63 printable bytes, no space,
/// comma or control character.
bool valid_channel_name(const std::string& name);

}  // namespace sg::auth
