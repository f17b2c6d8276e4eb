#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/config.hpp"

namespace sg::bus_check {

/// What `sg-bus-check send` is configured with: the `bus_check` section.
struct SendSettings {
  int64_t count = 1000;  ///< messages to send, 0 for no limit
  double rate_hz = 100;  ///< messages per second
};

/// Reads the `bus_check` section (range-checked; unknown keys refused).
SendSettings read_send_settings(const Config& config);

/// Messages for checking a bus end to end. Every field of a check message is derived from its
/// `utime` by a fixed pseudo-random rule, so a receiver (or a log reader) that knows only the
/// bytes can tell whether they arrived exactly as sent. Each type travels on its own channel,
/// `BUS_CHECK_<TYPE>`, so lcm-spy shows and decodes every stereograsp type.
///
///     std::vector<uint8_t> bytes = sg::bus_check::encode(type_index, utime);
///     bus.publish_raw(sg::bus_check::channel(type_index), bytes.data(), bytes.size());
///     ...
///     auto checked = sg::bus_check::verify(channel, data, size);  // nullopt: not a check channel
///     if (checked && !checked->intact) ++corrupt;

/// Channels start with this prefix.
inline constexpr const char* kChannelPrefix = "BUS_CHECK_";

/// How many message types take part (all of sg::MessageTypes).
int type_count();

/// The channel for the type with this index: `BUS_CHECK_` + the type name in capitals.
std::string channel(int type_index);

/// The type's name (`image_t`, ...).
std::string type_name(int type_index);

/// The encoded check message of type `type_index` for `utime`.
std::vector<uint8_t> encode(int type_index, int64_t utime);

/// The outcome of checking one received message.
struct Verdict {
  int type_index = -1;
  int64_t utime = 0;    ///< as decoded (0 when it did not decode)
  bool intact = false;  ///< decoded, and equal byte for byte to encode(type_index, utime)
};

/// Checks a message received on `channel_name`; nullopt when the channel is not a check channel.
std::optional<Verdict> verify(const std::string& channel_name, const uint8_t* data, int size);

// ---------------------------------------------------------------------------------------------
// A hostile bus (issue 15): packets that are almost, but not quite, messages of a type.

/// The values every 4-byte window of a message is set to, big-endian as LCM writes an int32:
/// 0, -1 (0xffffffff), 2^31 - 1 and 10^9. Over a length field they claim nothing, a negative
/// length, the largest length and a length far beyond the packet; over a double they make NaNs,
/// denormals and huge values.
inline constexpr uint32_t kWindowValues[] = {0x00000000u, 0xffffffffu, 0x7fffffffu, 1000000000u};

/// What a hostile packet is made of.
enum class HostileKind {
  kWindow,     ///< the typical message with one 4-byte window overwritten
  kRandom,     ///< the type's fingerprint, then random bytes of random length
  kTruncated,  ///< the typical message cut short
  kForeign,    ///< another type's typical message
};

/// One hostile packet: its bytes and one line saying how it was made.
struct HostilePacket {
  HostileKind kind = HostileKind::kWindow;
  std::string what;  ///< "image_t bytes 20-23 = 0x7fffffff", "blob_t random body 3: 57 bytes"
  std::vector<uint8_t> bytes;
};

/// What to make.
struct HostileSettings {
  uint64_t seed = 1;         ///< the random bodies derive from it (and the type)
  int random_bodies = 1000;  ///< K random bodies per type
  bool windows = true;       ///< every window x every kWindowValues entry
  bool truncations = true;   ///< the message cut at every length 0 .. size - 1
  bool foreign = true;       ///< every other type's typical message
};

/// The index of the type called `name` (`point3_t`), -1 when there is none.
int type_index(const std::string& name);

/// A typical well-formed message of the type: every string non-empty ("sg-<field>"), every
/// variable array 4 entries long (its length field 4), the numbers small and varied, and
/// plausible where a value could move the arm (an arm_cmd_t is a Cartesian move to
/// (0.45, 0, 0.20) m at half speed; a grasp_command_t asks to track): a mutation of it is as close
/// to a command that would be obeyed as a mutation can be.
std::vector<uint8_t> typical(int type_index);

/// The hostile packets of one type, in a fixed order (windows, random bodies, truncations,
/// foreign types); the same settings give the same packets. With n = typical(type).size():
/// 4 * (n - 11) windows (every byte offset from 8, after the fingerprint, to n - 4), K random
/// bodies (the 8-byte fingerprint, then 0 .. 2n random bytes), n truncations (0 .. n - 1 bytes),
/// and type_count() - 1 foreign messages.
std::vector<HostilePacket> hostile_packets(int type_index, const HostileSettings& settings);

/// A channel the system reads, and the type its readers expect there (DESIGN's channel list:
/// CAMERA_LEFT/RIGHT, BLOB_LEFT/RIGHT, OBJECT_POSITION, GROUND_TRUTH, OBJECT_TRAJECTORY,
/// ARM_COMMAND, ARM_STATUS, GRASP_COMMAND, GRASP_STATUS, SIM_ARM_STATE).
struct SystemChannel {
  std::string channel;
  std::string type;
};
const std::vector<SystemChannel>& system_channels();

/// One channel's share of an attack: the packets and how many were sent.
struct ChannelAttack {
  SystemChannel target;
  std::vector<HostilePacket> packets;
  int64_t sent = 0;
};

/// An attack: the channels' packets, sent round robin (one packet per channel in turn, so every
/// reader is under attack the whole time), numbered 0, 1, ... in that order.
struct HostilePlan {
  std::vector<ChannelAttack> channels;
  int64_t total() const;
  /// The packet with this number (and its channel), or nullptr beyond the end.
  const HostilePacket* at(int64_t number, std::string* channel = nullptr) const;
};

/// The plan for `channels` (names from system_channels(); empty: all of them). Throws
/// std::invalid_argument naming an unknown channel.
HostilePlan plan_attack(const std::vector<std::string>& channels, const HostileSettings& settings);

/// Sends the packets numbered `first` .. `last` (inclusive, clamped to the plan) through
/// `publish` at `rate_hz`, counting them per channel in `plan`; calls `progress(sent, due)` about
/// once a second; stops early when `stop()` says so. Returns how many were sent.
int64_t run_attack(
    HostilePlan& plan, int64_t first, int64_t last, double rate_hz,
    const std::function<bool(const std::string& channel, const HostilePacket&)>& publish,
    const std::function<void(int64_t sent, int64_t due)>& progress,
    const std::function<bool()>& stop);

/// One line per channel: the channel, its type, packets sent of planned, by kind.
std::string attack_summary(const HostilePlan& plan);

}  // namespace sg::bus_check
