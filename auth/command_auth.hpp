#pragma once

/// Signed commands (docs/security.md). LCM has no authentication: any host of the LAN can publish
/// on any channel. So every command that moves the arm (arm_cmd_t on ARM_COMMAND, grasp_command_t
/// on GRASP_COMMAND) carries
///   - `sender`: who signed it;
///   - `auth_counter`: strictly increasing per sender, across restarts too: the signer uses
///     max(last + 1, its clock in microseconds since the Unix epoch);
///   - `auth_tag`: HMAC-SHA-512-256 with the lab key (libsodium's crypto_auth) over
///         be32(length of channel) || channel || encode(message with auth_tag zeroed),
///     the encoding being LCM's, its 8-byte fingerprint included. All zero: unsigned.
/// The tag binds the channel, so a tag cannot be carried to another channel; it binds every
/// field, so nothing can be changed after signing. `sequence` stays the command's identity (a
/// resend of one command keeps its sequence and gets a new counter); the counter is only the
/// freshness of this copy.
///
/// The receiver's verdicts, in the order they are checked: kUnsigned (a zero tag), kBadTag (not
/// this key's tag for these bytes on this channel), kReplayed (a counter not newer than the last
/// *accepted* from that sender), kStale (a counter older than now - max_age, 30 s by default, so
/// a command captured before a receiver restarted cannot be replayed after it; or further ahead
/// of now than max_ahead: the sender's clock is wrong). Only an accepted command changes the
/// verifier's state, so no forged, replayed or stale message can lock a sender out: a forged STOP
/// with sequence 2^63-1 and sender "sg-grasp" is refused and leaves sg-grasp's next command
/// acceptable. The per-sender table holds at most max_senders (64) senders, the one longest
/// without an accepted command being forgotten first; only holders of the key can add one.
///
/// Why libsodium (Debian's libsodium-dev) rather than OpenSSL: it is small, its API is hard to
/// misuse (one call to tag, one to verify, fixed key and tag sizes, no modes or engines to pick),
/// crypto_auth_verify compares in constant time, and sodium_memzero wipes key material that the
/// compiler may not optimise away. HMAC-SHA-512-256 is crypto_auth's default construction.
///
///     const sg::auth::LabKey key = sg::auth::LabKey::load(sg::auth::default_key_path());
///     sg::auth::CommandSigner signer(key, "sg-arm-ctl");
///     signer.sign("ARM_COMMAND", command);                 // sets sender, counter, tag
///     bus.publish("ARM_COMMAND", command);
///     // receiver:
///     sg::auth::CommandVerifier verifier(key);
///     const sg::auth::Verification v = verifier.verify("ARM_COMMAND", command, sg::now_utime());
///     if (!v.accepted()) refuse(command, "unauthenticated: " + v.reason);

#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "auth/lab_key.hpp"
#include "common/clock.hpp"
#include "stereograsp/arm_cmd_t.hpp"
#include "stereograsp/grasp_command_t.hpp"

namespace sg::auth {

/// Bytes of an auth_tag (crypto_auth_BYTES).
constexpr std::size_t kTagSize = 32;

/// What became of a command at the receiver.
enum class Verdict : int {
  kAccepted = 0,  ///< signed with the lab key, fresh, newer than its sender's last
  kUnsigned = 1,  ///< auth_tag all zero
  kBadTag = 2,    ///< a tag, but not the lab key's for these bytes on this channel
  kReplayed = 3,  ///< auth_counter not newer than the last accepted from its sender
  kStale = 4,     ///< auth_counter outside now - max_age .. now + max_ahead
};
constexpr int kVerdicts = 5;

/// "accepted", "unsigned", "bad tag", "replayed", "stale".
const char* to_string(Verdict verdict);

struct VerifierSettings {
  /// s: a counter older than the receiver's clock minus this is stale. Bounds how long after it
  /// was sent a captured command can be replayed to a receiver that forgot its sender (a
  /// restart, or the sender evicted from the table); also the clock skew tolerated between hosts.
  double max_age = 30.0;
  /// s: a counter further ahead of the receiver's clock than this is stale too (a sender whose
  /// clock runs ahead would otherwise raise its own floor and lock its later commands out).
  double max_ahead = 30.0;
  /// Senders remembered; the one longest without an accepted command is forgotten first.
  std::size_t max_senders = 64;
};

/// A verdict and, unless accepted, why: short printable ASCII naming the sender and counter.
struct Verification {
  Verdict verdict = Verdict::kAccepted;
  std::string reason;
  bool accepted() const { return verdict == Verdict::kAccepted; }
};

/// Signs commands as one sender.
class CommandSigner {
 public:
  /// `sender` goes into every message it signs; `clock` gives the counter's floor (utime()).
  CommandSigner(const LabKey& key, std::string sender, Clock& clock = system_clock());

  /// Sets `sender`, a new `auth_counter` (max(last + 1, clock µs)) and `auth_tag` for `channel`.
  /// Throws std::runtime_error if the message cannot be encoded.
  void sign(const std::string& channel, stereograsp::arm_cmd_t& command);
  void sign(const std::string& channel, stereograsp::grasp_command_t& command);

  const std::string& sender() const { return sender_; }
  /// The last counter used (0 before any).
  int64_t last_counter() const { return last_; }

 private:
  template <class M>
  void sign_message(const std::string& channel, M& m);

  LabKey key_;
  std::string sender_;
  Clock& clock_;
  int64_t last_ = 0;
  std::vector<uint8_t> buffer_;  ///< reused: channel header and encoded message
};

/// Checks commands against the lab key and each sender's last accepted counter.
class CommandVerifier {
 public:
  explicit CommandVerifier(const LabKey& key, VerifierSettings settings = {});

  /// The verdict on `command` received on `channel` at `now_utime` (the receiver's clock, µs
  /// since the Unix epoch). Counts it; only kAccepted changes the sender table.
  Verification verify(const std::string& channel, const stereograsp::arm_cmd_t& command,
                      int64_t now_utime);
  Verification verify(const std::string& channel, const stereograsp::grasp_command_t& command,
                      int64_t now_utime);

  /// Commands given each verdict so far.
  int64_t count(Verdict verdict) const { return counts_[static_cast<int>(verdict)]; }
  /// Senders in the table (<= settings.max_senders).
  std::size_t senders() const { return senders_.size(); }
  const VerifierSettings& settings() const { return settings_; }

 private:
  struct Sender {
    int64_t counter = 0;   ///< the last accepted auth_counter
    uint64_t order = 0;    ///< when it was accepted: accepted_ at the time
  };

  template <class M>
  Verification verify_message(const std::string& channel, const M& m, int64_t now_utime);
  Verification check_counter(const std::string& sender, int64_t counter, int64_t now_utime);
  void remember(const std::string& sender, int64_t counter);
  Verification judge(Verdict verdict, std::string reason);

  LabKey key_;
  VerifierSettings settings_;
  std::unordered_map<std::string, Sender> senders_;
  std::array<int64_t, kVerdicts> counts_{};
  uint64_t accepted_ = 0;
  std::vector<uint8_t> buffer_;
};

/// The tag `command` should carry on `channel` under `key` (its own auth_tag ignored): for tests
/// and for fuzzing the check.
std::array<uint8_t, kTagSize> command_tag(const LabKey& key, const std::string& channel,
                                          const stereograsp::arm_cmd_t& command);
std::array<uint8_t, kTagSize> command_tag(const LabKey& key, const std::string& channel,
                                          const stereograsp::grasp_command_t& command);

}  // namespace sg::auth
