#pragma once

/// The C550's ACI link layer ("Advanced Communication Interface") as bytes: pure encoders and
/// decoders, no I/O, so they can be tested and fuzzed on their own (docs/arm.md).
///
///     AciHeader header{.slave = 1, .write = false, .memtype = kMemSession, .length = 1};
///     std::array<uint8_t, 13> bytes = encode_header(header);   // SOH ... ETX LRC
///     auto frames = encode_blocks(data);                       // STX ... ETB/ETX LRC each

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace sg::arm::aci {

inline constexpr uint8_t SOH = 0x01, STX = 0x02, ETX = 0x03, EOT = 0x04, ENQ = 0x05, ACK = 0x06,
                         NAK = 0x15, ETB = 0x17;
inline constexpr uint8_t kHostId = 0xFF;
inline constexpr int kBlockSize = 128;
inline constexpr int kHeaderSize = 13;
/// The most a header can describe: 255 full blocks and a last one of 128.
inline constexpr int kMaxTransfer = 256 * kBlockSize;

/// Memory types seen in public code.
inline constexpr uint8_t kMemSegment = 0x00;      ///< segment:offset memory
inline constexpr uint8_t kMemPointerList = 0x40;  ///< the RAPL pointer list, 4 bytes a pointer
inline constexpr uint8_t kMemSession = 0x48;      ///< a one-byte read that opens a host session

/// A link-layer violation: bad framing, bad LRC, a size with no encoding.
class AciError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The 8-bit additive checksum the C550 calls LRC: the sum of the bytes modulo 256.
uint8_t lrc(std::span<const uint8_t> bytes);

/// The slave address byte: slave number 1..127 plus 0x20.
uint8_t slave_byte(int slave);

/// Host enquiry `'R', slave+0x20, ENQ` and the controller's answer `'R', slave+0x20, ACK`.
std::array<uint8_t, 3> encode_enquiry(int slave);
std::array<uint8_t, 3> encode_enquiry_reply(int slave);

/// How a transfer of `length` bytes is split: `full_blocks` blocks of 128 then one of
/// `last_size` (1..128). Throws AciError for 0 bytes (the rule would give -1 full blocks) or more
/// than kMaxTransfer.
struct BlockLayout {
  int full_blocks = 0;
  int last_size = 0;
  int total_blocks() const { return full_blocks + 1; }
  int length() const { return full_blocks * kBlockSize + last_size; }
};
BlockLayout block_layout(int length);

/// One transfer's header, from the host's point of view.
struct AciHeader {
  int slave = 1;           ///< 1..127
  bool write = false;      ///< true: the host writes controller memory; false: it reads
  uint8_t memtype = kMemSegment;
  uint16_t offset = 0;
  uint16_t segment = 0;
  int length = 1;          ///< bytes, 1..kMaxTransfer
  bool operator==(const AciHeader&) const = default;
};

/// `SOH, slave+0x20, 0xFF, rw, memtype, full_blocks, last_size, ofs_lo, ofs_hi, seg_lo, seg_hi,
/// ETX, LRC` with LRC the sum of bytes 1..10.
std::array<uint8_t, kHeaderSize> encode_header(const AciHeader& header);
/// The header in 13 bytes; throws AciError naming what is wrong (framing, LRC, host id, layout).
AciHeader decode_header(std::span<const uint8_t> bytes);

/// The frames of `data`: `STX, 128 bytes, ETB, LRC` for each full block and `STX, n bytes, ETX,
/// LRC` for the last. Throws AciError for an empty or oversized transfer.
std::vector<std::vector<uint8_t>> encode_blocks(std::span<const uint8_t> data);

/// A received block frame.
struct Block {
  std::vector<uint8_t> data;
  bool last = false;  ///< ended with ETX (the last block) rather than ETB
};
/// Decodes one frame (`STX, data, ETB|ETX, LRC`); throws AciError on bad framing or LRC.
Block decode_block(std::span<const uint8_t> frame);

/// Frame length for a block holding `size` data bytes.
constexpr int block_frame_size(int size) { return size + 3; }

/// Printable name of a control byte ("ACK", "NAK", ..., or "0x41 'A'"), for error messages.
std::string byte_name(uint8_t byte);

}  // namespace sg::arm::aci
