#pragma once

/// LCM's UDP multicast wire format, read without LCM: the datagrams of a `udpm://` bus parsed,
/// and fragmented messages reassembled within fixed bounds. sg::Bus uses it to read chosen
/// channels on a socket of its own (Bus::subscribe_direct, issue 19); LCM keeps every other.
///
///     sg::LcmDatagramAssembler assembler;          // default bounds
///     auto wanted = [](std::string_view c) { return c == "CAMERA_LEFT"; };
///     auto refused = [](const std::string& why) { spdlog::warn("{}", why); };
///     if (auto m = assembler.add(sender, bytes, n, wanted, refused))
///       handle(m->channel, m->data, m->size);       // valid until the next add()
///
/// The format (LCM 1.3.1, lcm_udpm.c; every integer big-endian):
///   - a short message, one datagram: magic "LC02" (0x4c433032), uint32 sequence number, the
///     channel's name and a NUL, the message;
///   - a long message, in fragments: magic "LC03" (0x4c433033), uint32 sequence number, uint32
///     message size, uint32 the fragment's offset in the message, uint16 fragment number,
///     uint16 fragments in the message; fragment 0 then holds the channel and a NUL, each
///     fragment its part of the message. A sender sends a message's fragments in order, one
///     message at a time (LCM publishes under a lock).
///
/// Nothing in a datagram is trusted: a channel name of 1 to 63 bytes (LCM's limit), a fragment
/// inside its message, a message no larger than Limits::max_message, at most Limits::max_senders
/// messages in assembly at once and Limits::max_held bytes of buffers (the oldest dropped for a
/// newer message). A message is complete
/// only when its fragments came in order and covered it exactly, so no byte of it is one that
/// did not arrive; one that misses a fragment is dropped and reported, as is every datagram that
/// breaks the format (a message whose sender falls silent before its last fragment is held until
/// its slot is wanted, then reported). Memory: at most max_held bytes of buffers (80 MiB by
/// default), each committed only as fragments fill it.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sg {

/// One datagram's header, as parse_lcm_datagram read it.
struct LcmDatagram {
  bool fragment = false;          ///< LC03 (part of a long message) rather than LC02
  uint32_t seqno = 0;             ///< the sender's message sequence number
  std::string_view channel;       ///< empty in fragments after the first
  const uint8_t* data = nullptr;  ///< this datagram's part of the message
  size_t size = 0;                ///< its bytes
  uint32_t message_size = 0;      ///< LC03: the whole message's bytes (LC02: size)
  uint32_t offset = 0;            ///< LC03: where `data` goes in the message
  uint16_t fragment_no = 0, fragments = 1;
};

inline constexpr uint32_t kLcmMagicShort = 0x4c433032;  // "LC02"
inline constexpr uint32_t kLcmMagicLong = 0x4c433033;   // "LC03"
inline constexpr size_t kLcmMaxChannel = 63;            // LCM_MAX_CHANNEL_NAME_LENGTH

/// Reads one datagram's header; on bytes that break the format returns nothing and sets `why`
/// (one line: "an LC03 fragment 3 of 2", "a channel name without its NUL", ...). Checks the
/// datagram alone: a fragment's place in its message is checked against the message's size.
std::optional<LcmDatagram> parse_lcm_datagram(const uint8_t* bytes, size_t size, std::string* why);

/// A whole message on a wanted channel, valid until the assembler's next add().
struct LcmMessage {
  std::string_view channel;
  const uint8_t* data = nullptr;
  size_t size = 0;
};

/// Reassembles the messages of wanted channels from a bus's datagrams (see the file comment).
class LcmDatagramAssembler {
 public:
  struct Limits {
    /// The largest message assembled: a 4096 x 4096 RGB image_t (safe_decode's bound for its
    /// data, 64 MiB) and its header.
    size_t max_message = (size_t{64} << 20) + 4096;
    /// Messages in assembly at once, one per sender (LCM's sender never interleaves two): a
    /// stereo rig's two cameras and room for two more; at most 4 x 64 MiB held.
    size_t max_senders = 4;
    /// Bytes of buffers held at once, in assembly or kept for the next message: the oldest
    /// assemblies are dropped for a newer one that would pass it. Not less than max_message.
    size_t max_held = size_t{80} << 20;
  };

  explicit LcmDatagramAssembler(Limits limits);
  LcmDatagramAssembler() : LcmDatagramAssembler(Limits{}) {}
  ~LcmDatagramAssembler();
  LcmDatagramAssembler(const LcmDatagramAssembler&) = delete;
  LcmDatagramAssembler& operator=(const LcmDatagramAssembler&) = delete;

  using Wanted = std::function<bool(std::string_view channel)>;
  using Refused = std::function<void(const std::string& why)>;

  /// Takes one datagram from `sender` (any number that tells senders apart: address and port).
  /// Returns a message when this datagram completes one on a channel `wanted` accepts; calls
  /// `refused` with one line for a datagram that breaks the format or a wanted message that
  /// could not be completed (a lost, repeated or reordered fragment). Datagrams of channels
  /// not wanted are skipped without a word, their fragments too.
  std::optional<LcmMessage> add(uint64_t sender, const uint8_t* bytes, size_t size,
                                const Wanted& wanted, const Refused& refused);

  /// Messages in assembly now, and the bytes of buffers held (for tests of the bounds).
  size_t in_assembly() const;
  size_t held() const;

 private:
  struct Assembly;
  Assembly* assembly_of(uint64_t sender);
  Assembly& start(uint64_t sender);
  void make_room(Assembly& slot, size_t size, const Refused& refused);
  std::optional<LcmMessage> continue_fragment(Assembly& a, const LcmDatagram& d,
                                              const Refused& refused);

  Limits limits_;
  std::vector<std::unique_ptr<Assembly>> assemblies_;
  uint64_t clock_ = 0;  // orders assemblies by their last datagram, for the eviction
};

}  // namespace sg
