#pragma once

/// The on-disk format of an lcm-logger file, and the checks that keep LCM's own reader away from
/// a damaged one. LCM 1.3.1's reader trusts the lengths in an event header: it allocates
/// `datalen + 1` bytes as an int, so a data length of 0x7fffffff becomes a failed calloc that it
/// then writes through (measured: sg-report, sg-bus-check verify-log and sg-predictor train
/// crashed on such a log).
///
/// An event is a 28-byte header: magic 0xEDA1DA01, int64 event number, int64 timestamp
/// (microseconds), int32 channel length, int32 data length, all big-endian; then the channel
/// (not terminated) and the data.
///
///     sg::log_format::EventHeader h;
///     if (sg::log_format::parse_header(bytes, h) && h.fits(offset, file_size)) { ... }

#include <cstdint>
#include <cstdio>
#include <string>

namespace sg::log_format {

constexpr uint8_t kMagic[4] = {0xED, 0xA1, 0xDA, 0x01};
constexpr int kHeaderSize = 28;
constexpr int64_t kMaxChannelLength = 1000;  ///< LCM refuses longer ones too
/// No real event comes near 256 MiB (an image_t is at most 64 MiB, common/safe_decode.hpp).
constexpr int64_t kMaxDataLength = int64_t{1} << 28;

/// The fields of one event header.
struct EventHeader {
  int64_t event_number = 0;
  int64_t recv_utime = 0;
  int64_t channel_length = 0;
  int64_t data_length = 0;
  /// Bytes of the whole event on disk.
  int64_t event_size() const { return kHeaderSize + channel_length + data_length; }
  /// True when the event starting at `offset` ends within a file of `file_size` bytes.
  bool fits(int64_t offset, int64_t file_size) const { return offset + event_size() <= file_size; }
};

/// Reads the 28 header bytes at `p` into `h`; false when there is no magic at `p` or a length
/// is implausible (channel not 1..kMaxChannelLength, data not 0..kMaxDataLength).
bool parse_header(const uint8_t* p, EventHeader& h);

/// Walks every event of an open log from its start: "" when each header is plausible and each
/// event whole, else where and how the first one is not ("byte 1234: no event header",
/// "byte 1234: an event of 2147483690 bytes in a 5000-byte file").
std::string first_damage(std::FILE* f, int64_t file_size);

}  // namespace sg::log_format
