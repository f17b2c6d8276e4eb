#pragma once

/// Every datum vouched for (docs/security.md): each publisher proves to each reader the lab names
/// on a channel that the message is its own, unchanged and new, and each reader believes only the
/// publishers the lab allows on that channel. The proof is one 16-byte tag per reader in the
/// message's trailer (common/vouch_trailer.hpp):
///
///     k   = BLAKE2b-256(key = K(sender -> reader), "sg-otk-v1" || u8 |channel| || channel
///                       || u8 |sender| || sender || be32 instance || be64 counter)
///     tag = Poly1305(k, LCM encoding)
///
/// k is a one-time key: the counter never repeats within an instance (below), so no two messages
/// share one, which is what Poly1305 (the MAC of crypto_secretbox) asks. It binds the channel,
/// sender, run and counter; the tag binds every byte of the message. Poly1305 reads 44 KB in
/// 11 us here where BLAKE2b takes 45 us: a camera image costs its reader a quarter as much.
///
/// K(sender -> reader) is a key only that pair holds: BLAKE2b-256 keyed with the lab key over
/// "sg-pair-v1" || u8 |sender| || sender || u8 |reader| || reader. So a reader cannot forge what
/// a sender says to another reader, and a host that holds only some processes' credentials can
/// speak as those processes and no others: what a public-key signature gives, at the cost of a
/// MAC per reader (Ed25519 costs 35 us to sign and 50-70 us to verify here; a tag of a 1 KB
/// message, about 1 us).
/// The counter is max(last + 1, the sender's clock in us): a reader refuses a counter not newer
/// than the last it accepted from that instance on that channel (a replay), or further than
/// max_age behind or max_ahead ahead of its own clock (a log played onto a live bus, a clock off
/// by more than the lab tolerates).
///
/// Who may publish on a channel, and who reads it, is the lab's ChannelRights; a process's
/// Credentials hold its identity and the pair keys it needs for them: with the lab key, derived
/// for every pair (one host, a bench); from `sg-lab`'s credential files, only its own.
///
///     const sg::auth::Credentials me =
///         sg::auth::credentials_from_lab_key(key, "sg-predictor",
///         sg::auth::default_channel_rights());
///     bus.set_guard(std::make_shared<sg::auth::DataGuard>(me));
///     bus.publish("OBJECT_TRAJECTORY", t);     // vouched for sg-grasp and sg-viewer
///     // sg-grasp's bus, likewise guarded, hands its handler only what sg-predictor vouched for

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "auth/lab_key.hpp"
#include "common/clock.hpp"
#include "common/message_guard.hpp"
#include "common/vouch_trailer.hpp"

namespace sg::auth {

/// Who may publish on a channel, and which readers a publisher vouches for it to.
struct ChannelRight {
  std::string channel;
  std::vector<std::string> publishers;
  std::vector<std::string> readers;
};
using ChannelRights = std::vector<ChannelRight>;

/// Every identity (program) of the system.
const std::vector<std::string>& known_identities();

/// The system's channels as docs/design.md draws them: CAMERA_* from sg-camera-sim (and sg-vision
/// with --publish-images), GROUND_TRUTH from sg-camera-sim, SIM_ARM_STATE from sg-c550-sim,
/// BLOB_* and OBJECT_POSITION from sg-vision, OBJECT_TRAJECTORY from sg-predictor, ARM_COMMAND
/// from sg-grasp, sg-arm-ctl and sg-calibrate, ARM_STATUS from sg-arm-driver, GRASP_COMMAND from
/// sg-grasp-ctl, GRASP_STATUS from sg-grasp, PROCESS_STATUS from everyone; each read by the
/// programs that subscribe to it.
const ChannelRights& default_channel_rights();

/// A 32-byte key of a pair; wiped when destroyed.
class PairKey {
 public:
  static constexpr std::size_t kSize = 32;
  PairKey() = default;
  explicit PairKey(const std::array<uint8_t, kSize>& bytes) : bytes_(bytes) {}
  PairKey(const PairKey& other) = default;
  PairKey& operator=(const PairKey& other) = default;
  ~PairKey();
  const std::array<uint8_t, kSize>& bytes() const { return bytes_; }

 private:
  std::array<uint8_t, kSize> bytes_{};
};

/// K(sender -> reader) under the lab key.
PairKey pair_key(const LabKey& lab, const std::string& sender, const std::string& reader);

/// One peer of a process: the key they share and the channels it covers (for a `send` peer, the
/// channels this process vouches to it on; for a `receive` peer, the channels it may publish on).
struct Peer {
  std::string name;
  PairKey key;
  std::vector<std::string> channels;
};

/// What one process holds: who it is, whom it vouches to on which channels, whom it believes on
/// which channels.
struct Credentials {
  std::string identity;
  std::vector<Peer> send;
  std::vector<Peer> receive;
  /// The key that signs and checks commands (auth::command_key), for a process that sends or
  /// obeys them; none for the others.
  std::optional<LabKey> command_key;
};

/// The channels that carry commands: whoever publishes or reads them holds the command key.
bool is_command_channel(const std::string& channel);

/// `identity`'s credentials under the lab key and `rights`: a send peer per reader of each channel
/// it may publish on, a receive peer per publisher of each channel it reads. Throws
/// std::invalid_argument for an identity that is not a valid_vouch_name().
Credentials credentials_from_lab_key(const LabKey& lab, const std::string& identity,
                                     const ChannelRights& rights = default_channel_rights());

struct DataGuardSettings {
  /// s: a counter older than this behind the reader's clock is stale (a log played onto a live
  /// bus; a message captured before a reader restarted); also the clock skew tolerated.
  double max_age = 30.0;
  /// s: a counter further ahead of the reader's clock than this is stale.
  double max_ahead = 30.0;
  /// (instance, channel) counters remembered; the one longest without an accepted message goes.
  std::size_t max_streams = 512;
};

/// Vouches for what a process sends and checks what it receives (sg::MessageGuard).
class DataGuard final : public MessageGuard {
 public:
  /// `clock` gives the counter's floor (utime()); `instance` tells this run from others of the
  /// same identity (0: a random one).
  explicit DataGuard(Credentials credentials, DataGuardSettings settings = {},
                     Clock& clock = system_clock(), uint32_t instance = 0);

  const std::string& identity() const override { return credentials_.identity; }
  void vouch(const std::string& channel, std::vector<uint8_t>& message) override;
  GuardResult check(const std::string& channel, const uint8_t* data, std::size_t size,
                    int64_t now_utime) override;

  uint32_t instance() const { return instance_; }
  /// Messages given each verdict so far.
  int64_t count(GuardVerdict verdict) const { return counts_[static_cast<int>(verdict)]; }
  /// (instance, channel) streams remembered.
  std::size_t streams() const { return streams_.size(); }

 private:
  struct Stream {
    int64_t counter = 0;  ///< the last accepted
    uint64_t order = 0;   ///< accepted_ when it was
  };
  /// The send peers (indices into credentials_.send) for `channel`, found once.
  const std::vector<std::size_t>& readers_of(const std::string& channel);
  GuardResult judge(GuardVerdict verdict, std::string sender, std::string reason);
  GuardResult check_counter(const std::string& channel, const VouchTrailer& t, int64_t now_utime);
  void remember(const std::string& stream, int64_t counter);

  Credentials credentials_;
  DataGuardSettings settings_;
  Clock& clock_;
  uint32_t instance_;
  int64_t last_counter_ = 0;
  std::unordered_map<std::string, std::vector<std::size_t>> readers_;
  std::unordered_map<std::string, Stream> streams_;
  std::array<int64_t, kGuardVerdicts> counts_{};
  uint64_t accepted_ = 0;
};

/// A guard for a tool that stands in for one of the lab's processes (a benchmark feeding frames
/// as sg-camera-sim, a test harness): it vouches for what it publishes as that identity with a
/// DataGuard, and believes whatever arrives, trailers taken off. It looks; it does not steer.
class VouchingPublisher final : public MessageGuard {
 public:
  explicit VouchingPublisher(Credentials credentials) : inner_(std::move(credentials)) {}
  const std::string& identity() const override { return inner_.identity(); }
  void vouch(const std::string& channel, std::vector<uint8_t>& message) override {
    inner_.vouch(channel, message);
  }
  GuardResult check(const std::string&, const uint8_t* data, std::size_t size, int64_t) override {
    GuardResult r;
    r.payload_size = vouched_payload_size(data, size);
    return r;
  }
  DataGuard& inner() { return inner_; }

 private:
  DataGuard inner_;
};

/// The one-time key k of a message (above), for tests and the fuzzer.
std::array<uint8_t, 32> one_time_key(const PairKey& key, const std::string& channel,
                                     const VouchTrailer& trailer);
/// The tag a reader holding `key` expects on `size` bytes at `payload` with `trailer`.
std::array<uint8_t, kVouchTagSize> vouch_tag(const PairKey& key, const std::string& channel,
                                             const VouchTrailer& trailer, const uint8_t* payload,
                                             std::size_t size);

}  // namespace sg::auth
