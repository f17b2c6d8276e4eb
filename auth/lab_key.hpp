#pragma once

/// The lab key: the one secret that every lab machine holds and that signs every command which
/// moves the arm (ARM_COMMAND, GRASP_COMMAND; docs/security.md). It is 32 random bytes
/// (libsodium's randombytes_buf), kept in a key file as 64 lowercase hex characters and a newline,
/// mode 0600 (readable by its owner only). A key file that others may read is refused, so a key
/// that leaked through a careless copy is never used without someone noticing.
///
///     sg::auth::write_new_key_file("/tmp/lab.key");           // O_EXCL, mode 0600
///     const sg::auth::LabKey key = sg::auth::LabKey::load(sg::auth::default_key_path());
///     // key.bytes() -> the 32 bytes for crypto_auth; wiped (sodium_memzero) on destruction

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace sg::auth {

/// A key file that cannot be used: one line, "lab key PATH: reason".
class LabKeyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The 32-byte key shared by the lab's machines. Copies are independent; each wipes its bytes
/// when destroyed.
class LabKey {
 public:
  static constexpr std::size_t kSize = 32;  ///< bytes (crypto_auth_KEYBYTES)

  /// Reads a key file. Throws LabKeyError naming the path when it is missing or unreadable, not a
  /// regular file, readable or writable by group or others (mode & 077: "chmod 600 PATH"), or
  /// not exactly 64 hex characters (one trailing newline allowed).
  static LabKey load(const std::string& path);

  /// A key from its bytes (tests, benchmarks).
  explicit LabKey(const std::array<uint8_t, kSize>& bytes);
  LabKey(const LabKey& other);
  LabKey& operator=(const LabKey& other);
  ~LabKey();

  const std::array<uint8_t, kSize>& bytes() const { return bytes_; }

 private:
  LabKey() = default;
  std::array<uint8_t, kSize> bytes_{};
};

/// Writes a new random key to `path` (64 hex characters and a newline, mode 0600), creating the
/// parent folder (mode 0700) when missing. Refuses an existing file unless `replace`, in which
/// case the new key goes to a temporary file beside it that is renamed over the old one. Throws
/// LabKeyError.
void write_new_key_file(const std::string& path, bool replace = false);

/// The text of a secret file (a lab key, a process's credentials) of at most `limit` bytes, with
/// LabKey::load's refusals: missing, unreadable, not a regular file, readable or writable by group
/// or others, and larger than `limit`. Throws LabKeyError "lab key PATH: ...".
std::string read_secret_file(const std::string& path, std::size_t limit);

/// Writes `text` to `path`, mode 0600, through a temporary file beside it renamed over it (so a
/// reader never sees half a file), creating the parent folder (mode 0700). Throws LabKeyError.
void write_secret_file(const std::string& path, const std::string& text);

/// The key that signs commands (ARM_COMMAND, GRASP_COMMAND): BLAKE2b-256 keyed with the lab key
/// over "sg-command-v1". Only the processes that send or obey commands hold it, so a host with the
/// cameras' credentials cannot sign one.
LabKey command_key(const LabKey& lab);

/// The lab key of `generation`: the lab key itself for 0, else BLAKE2b-256 keyed with it over
/// "sg-generation-v1" || be32 generation. `sg-lab revoke` moves a lab to the next generation, so
/// the credentials of the one it revokes, derived from the last, no longer match anyone's.
LabKey generation_key(const LabKey& lab, uint32_t generation);

/// Where programs look for the key: $SG_LAB_KEY when set and not empty, else
/// $HOME/.config/stereograsp/lab.key. Throws LabKeyError when neither variable is set.
std::string default_key_path();

/// Calls sodium_init() once (thread-safe); throws std::runtime_error if libsodium cannot start.
void ensure_sodium();

}  // namespace sg::auth
