// Drives the ACI link layer's decoders (arm_driver/aci.hpp) with what a serial line may carry:
// the first 13 bytes as a transfer header (decode_header), the rest as one block frame
// (decode_block), and the whole input as the data of a transfer (encode_blocks).
// Asserts, beyond not crashing:
//  - only AciError is thrown;
//  - a header that decodes re-encodes to the same 13 bytes (every byte, the LRC included, is
//    determined by the decoded value), and block_layout() of its length gives back its two layout
//    bytes;
//  - a block frame that decodes re-encodes (encode_blocks) to the same frame;
//  - the frames encode_blocks makes of any 1..32768 bytes decode back to those bytes, the last
//    one alone ending with ETX.

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "arm_driver/aci.hpp"
#include "fuzz/fuzz_support.hpp"

namespace aci = sg::arm::aci;

namespace {

void header(std::span<const uint8_t> bytes) {
  aci::AciHeader h;
  try {
    h = aci::decode_header(bytes);
  } catch (const aci::AciError&) {
    return;
  }
  const auto again = aci::encode_header(h);
  SG_FUZZ_CHECK(std::equal(again.begin(), again.end(), bytes.begin(), bytes.end()),
                "a decoded header re-encodes to other bytes");
  const aci::BlockLayout layout = aci::block_layout(h.length);
  SG_FUZZ_CHECK(layout.full_blocks == bytes[5] && layout.last_size == bytes[6],
                "layout of %d bytes is %d+%d, header said %d+%d", h.length, layout.full_blocks,
                layout.last_size, bytes[5], bytes[6]);
}

void block(std::span<const uint8_t> frame) {
  aci::Block b;
  try {
    b = aci::decode_block(frame);
  } catch (const aci::AciError&) {
    return;
  }
  // A non-last block is the first of a longer transfer; one byte more makes encode_blocks end it.
  std::vector<uint8_t> data = b.data;
  if (!b.last) data.push_back(0);
  const auto frames = aci::encode_blocks(data);
  SG_FUZZ_CHECK(std::equal(frames[0].begin(), frames[0].end(), frame.begin(), frame.end()),
                "a decoded block of %zu bytes re-encodes to other bytes", b.data.size());
}

void transfer(std::span<const uint8_t> data) {
  if (data.empty() || data.size() > static_cast<size_t>(aci::kMaxTransfer)) return;
  std::vector<uint8_t> joined;
  const auto frames = aci::encode_blocks(data);
  for (size_t i = 0; i < frames.size(); ++i) {
    const aci::Block b = aci::decode_block(frames[i]);  // must not throw
    SG_FUZZ_CHECK(b.last == (i + 1 == frames.size()), "block %zu of %zu: wrong end byte", i,
                  frames.size());
    joined.insert(joined.end(), b.data.begin(), b.data.end());
  }
  SG_FUZZ_CHECK(std::equal(joined.begin(), joined.end(), data.begin(), data.end()),
                "%zu bytes do not survive encode_blocks and decode_block", data.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> input(data, size);
  if (size >= aci::kHeaderSize) {
    header(input.first(aci::kHeaderSize));
    block(input.subspan(aci::kHeaderSize));
  }
  block(input);
  transfer(input);
  for (size_t i = 0; i < std::min<size_t>(size, 4); ++i) (void)aci::byte_name(data[i]);
  return 0;
}
