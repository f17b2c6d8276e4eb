#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/config.hpp"

namespace sg::bus_check {

/// What `sg-bus-check send` is configured with: the `bus_check` section.
struct SendSettings {
  int64_t count = 1000;   ///< messages to send, 0 for no limit
  double rate_hz = 100;   ///< messages per second
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

}  // namespace sg::bus_check
