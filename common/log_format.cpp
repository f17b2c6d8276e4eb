#include "common/log_format.hpp"

#include <cstring>

namespace sg::log_format {
namespace {

int64_t big_endian(const uint8_t* p, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return n == 4 ? static_cast<int64_t>(static_cast<int32_t>(v)) : static_cast<int64_t>(v);
}

}  // namespace

bool parse_header(const uint8_t* p, EventHeader& h) {
  if (std::memcmp(p, kMagic, 4) != 0) return false;
  h.event_number = big_endian(p + 4, 8);
  h.recv_utime = big_endian(p + 12, 8);
  h.channel_length = big_endian(p + 20, 4);
  h.data_length = big_endian(p + 24, 4);
  return h.channel_length > 0 && h.channel_length <= kMaxChannelLength && h.data_length >= 0 &&
         h.data_length <= kMaxDataLength;
}

std::string first_damage(std::FILE* f, int64_t file_size) {
  int64_t pos = 0;
  uint8_t bytes[kHeaderSize];
  while (pos < file_size) {
    const std::string at = "byte " + std::to_string(pos) + ": ";
    if (fseeko(f, pos, SEEK_SET) != 0) return at + "cannot seek";
    if (pos + kHeaderSize > file_size || std::fread(bytes, 1, kHeaderSize, f) != kHeaderSize) {
      return at + "the file ends inside an event header";
    }
    EventHeader h;
    if (!parse_header(bytes, h)) return at + "no plausible event header";
    if (!h.fits(pos, file_size)) {
      return at + "an event of " + std::to_string(h.event_size()) + " bytes in a " +
             std::to_string(file_size) + "-byte file";
    }
    pos += h.event_size();
  }
  return {};
}

}  // namespace sg::log_format
