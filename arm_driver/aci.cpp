#include "arm_driver/aci.hpp"

#include <cstdio>
#include <numeric>

namespace sg::arm::aci {

uint8_t lrc(std::span<const uint8_t> bytes) {
  return static_cast<uint8_t>(std::accumulate(bytes.begin(), bytes.end(), 0u));
}

uint8_t slave_byte(int slave) {
  if (slave < 1 || slave > 127) {
    throw AciError("slave number " + std::to_string(slave) + " is outside 1..127");
  }
  return static_cast<uint8_t>(slave + 0x20);
}

std::array<uint8_t, 3> encode_enquiry(int slave) { return {'R', slave_byte(slave), ENQ}; }

std::array<uint8_t, 3> encode_enquiry_reply(int slave) { return {'R', slave_byte(slave), ACK}; }

BlockLayout block_layout(int length) {
  if (length <= 0) {
    throw AciError("an ACI transfer of " + std::to_string(length) +
                   " bytes has no encoding (at least 1 byte)");
  }
  if (length > kMaxTransfer) {
    throw AciError("an ACI transfer of " + std::to_string(length) + " bytes is over the " +
                   std::to_string(kMaxTransfer) + "-byte limit");
  }
  BlockLayout layout{length / kBlockSize, length % kBlockSize};
  if (layout.last_size == 0) {
    layout.full_blocks -= 1;
    layout.last_size = kBlockSize;
  }
  return layout;
}

std::array<uint8_t, kHeaderSize> encode_header(const AciHeader& header) {
  const BlockLayout layout = block_layout(header.length);
  std::array<uint8_t, kHeaderSize> bytes{SOH,
                                         slave_byte(header.slave),
                                         kHostId,
                                         static_cast<uint8_t>(header.write ? 0x01 : 0x00),
                                         header.memtype,
                                         static_cast<uint8_t>(layout.full_blocks),
                                         static_cast<uint8_t>(layout.last_size),
                                         static_cast<uint8_t>(header.offset & 0xFF),
                                         static_cast<uint8_t>(header.offset >> 8),
                                         static_cast<uint8_t>(header.segment & 0xFF),
                                         static_cast<uint8_t>(header.segment >> 8),
                                         ETX,
                                         0};
  bytes[12] = lrc(std::span(bytes).subspan(1, 10));
  return bytes;
}

AciHeader decode_header(std::span<const uint8_t> bytes) {
  if (bytes.size() != kHeaderSize) {
    throw AciError("ACI header of " + std::to_string(bytes.size()) + " bytes (expected 13)");
  }
  if (bytes[0] != SOH) throw AciError("ACI header starts with " + byte_name(bytes[0]));
  if (bytes[11] != ETX) throw AciError("ACI header has " + byte_name(bytes[11]) + " for ETX");
  const uint8_t expected = lrc(bytes.subspan(1, 10));
  if (bytes[12] != expected) {
    throw AciError("ACI header LRC is " + std::to_string(bytes[12]) + ", expected " +
                   std::to_string(expected));
  }
  if (bytes[2] != kHostId) throw AciError("ACI header host id is " + byte_name(bytes[2]));
  if (bytes[1] < 0x21 || bytes[1] > 0x9F) {
    throw AciError("ACI header slave byte " + byte_name(bytes[1]) + " is outside 0x21..0x9F");
  }
  if (bytes[3] > 1) throw AciError("ACI header rw byte is " + byte_name(bytes[3]));
  if (bytes[6] < 1 || bytes[6] > kBlockSize) {
    throw AciError("ACI header last block size " + std::to_string(bytes[6]) +
                   " is outside 1..128");
  }
  AciHeader header;
  header.slave = bytes[1] - 0x20;
  header.write = bytes[3] == 1;
  header.memtype = bytes[4];
  header.length = bytes[5] * kBlockSize + bytes[6];
  header.offset = static_cast<uint16_t>(bytes[7] | (bytes[8] << 8));
  header.segment = static_cast<uint16_t>(bytes[9] | (bytes[10] << 8));
  return header;
}

std::vector<std::vector<uint8_t>> encode_blocks(std::span<const uint8_t> data) {
  const BlockLayout layout = block_layout(static_cast<int>(data.size()));
  std::vector<std::vector<uint8_t>> frames;
  frames.reserve(layout.total_blocks());
  for (int i = 0; i < layout.total_blocks(); ++i) {
    const bool last = i == layout.full_blocks;
    const auto chunk = data.subspan(i * kBlockSize, last ? layout.last_size : kBlockSize);
    std::vector<uint8_t> frame;
    frame.reserve(block_frame_size(static_cast<int>(chunk.size())));
    frame.push_back(STX);
    frame.insert(frame.end(), chunk.begin(), chunk.end());
    frame.push_back(last ? ETX : ETB);
    frame.push_back(lrc(chunk));
    frames.push_back(std::move(frame));
  }
  return frames;
}

Block decode_block(std::span<const uint8_t> frame) {
  if (frame.size() < 4 || frame.size() > block_frame_size(kBlockSize)) {
    throw AciError("ACI block frame of " + std::to_string(frame.size()) +
                   " bytes (expected 4..131)");
  }
  if (frame[0] != STX) throw AciError("ACI block starts with " + byte_name(frame[0]));
  const uint8_t end = frame[frame.size() - 2];
  if (end != ETB && end != ETX) {
    throw AciError("ACI block ends with " + byte_name(end) + " (expected ETB or ETX)");
  }
  const auto data = frame.subspan(1, frame.size() - 3);
  if (end == ETB && data.size() != kBlockSize) {
    throw AciError("ACI block of " + std::to_string(data.size()) + " bytes ends with ETB");
  }
  if (frame.back() != lrc(data)) {
    throw AciError("ACI block LRC is " + std::to_string(frame.back()) + ", expected " +
                   std::to_string(lrc(data)));
  }
  return {std::vector<uint8_t>(data.begin(), data.end()), end == ETX};
}

std::string byte_name(uint8_t byte) {
  switch (byte) {
    case SOH: return "SOH";
    case STX: return "STX";
    case ETX: return "ETX";
    case EOT: return "EOT";
    case ENQ: return "ENQ";
    case ACK: return "ACK";
    case NAK: return "NAK";
    case ETB: return "ETB";
    default: break;
  }
  char text[16];
  if (byte >= 0x20 && byte < 0x7F) {
    std::snprintf(text, sizeof text, "0x%02X '%c'", byte, byte);
  } else {
    std::snprintf(text, sizeof text, "0x%02X", byte);
  }
  return text;
}

}  // namespace sg::arm::aci
