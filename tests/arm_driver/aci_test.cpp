// The ACI link layer of the C550 as bytes: the LRC, the enquiry, the 13-byte header, the split of
// a transfer into 128-byte blocks and the block frames. Every expected byte is derived by hand
// from /work/shared/reference/c550-aci.md (the comments show the arithmetic).

#include "arm_driver/aci.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace sg::arm::aci {
namespace {

/// `n` bytes all equal to `value`.
std::vector<uint8_t> filled(size_t n, uint8_t value) { return std::vector<uint8_t>(n, value); }

/// `n` bytes counting 0, 1, ..., 255, 0, 1, ...
std::vector<uint8_t> counting(size_t n) {
  std::vector<uint8_t> data(n);
  for (size_t i = 0; i < n; ++i) data[i] = static_cast<uint8_t>(i);
  return data;
}

// ---- LRC ----

// The LRC of nothing is 0 and of small sequences is their plain sum.
TEST(AciLrc, SmallSequencesAreTheirSum) {
  EXPECT_EQ(lrc({}), 0x00);
  const std::vector<uint8_t> one_two_three{0x01, 0x02, 0x03};  // 1 + 2 + 3 = 6
  EXPECT_EQ(lrc(one_two_three), 0x06);
  const std::vector<uint8_t> abc{'A', 'B', 'C'};  // 0x41 + 0x42 + 0x43 = 0xC6
  EXPECT_EQ(lrc(abc), 0xC6);
}

// The sum wraps modulo 256.
TEST(AciLrc, WrapsModulo256) {
  const std::vector<uint8_t> ff_one{0xFF, 0x01};  // 0x100 mod 0x100 = 0x00
  EXPECT_EQ(lrc(ff_one), 0x00);
  const std::vector<uint8_t> three_80{0x80, 0x80, 0x80};  // 0x180 mod 0x100 = 0x80
  EXPECT_EQ(lrc(three_80), 0x80);
  // 256 x 0xFF = 0xFF00, low byte 0x00.
  EXPECT_EQ(lrc(filled(256, 0xFF)), 0x00);
  // 0 + 1 + ... + 255 = 255 * 256 / 2 = 32640 = 0x7F80, low byte 0x80.
  EXPECT_EQ(lrc(counting(256)), 0x80);
  // 0 + 1 + ... + 127 = 127 * 128 / 2 = 8128 = 0x1FC0, low byte 0xC0.
  EXPECT_EQ(lrc(counting(128)), 0xC0);
}

// The LRC of a header is the sum of its bytes 1..10 (slave 1 session read: 0x69, see below).
TEST(AciLrc, OfHeaderBytesOneToTen) {
  // 0x21 + 0xFF + 0x00 + 0x48 + 0x00 + 0x01 + 0 + 0 + 0 + 0 = 0x169 -> 0x69.
  const std::vector<uint8_t> body{0x21, 0xFF, 0x00, 0x48, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(lrc(body), 0x69);
}

// ---- Enquiry ----

// The slave byte is the slave number plus 0x20 for 1..127 and refused outside.
TEST(AciEnquiry, SlaveByte) {
  EXPECT_EQ(slave_byte(1), 0x21);
  EXPECT_EQ(slave_byte(127), 0x9F);  // 127 + 32 = 159 = 0x9F
  EXPECT_THROW(slave_byte(0), AciError);
  EXPECT_THROW(slave_byte(128), AciError);
  EXPECT_THROW(slave_byte(-1), AciError);
}

// Slave 1: enquiry 'R' 0x21 ENQ, answer 'R' 0x21 ACK.
TEST(AciEnquiry, Slave1) {
  EXPECT_EQ(encode_enquiry(1), (std::array<uint8_t, 3>{0x52, 0x21, 0x05}));
  EXPECT_EQ(encode_enquiry_reply(1), (std::array<uint8_t, 3>{0x52, 0x21, 0x06}));
}

// Slave 127: enquiry 'R' 0x9F ENQ, answer 'R' 0x9F ACK.
TEST(AciEnquiry, Slave127) {
  EXPECT_EQ(encode_enquiry(127), (std::array<uint8_t, 3>{0x52, 0x9F, 0x05}));
  EXPECT_EQ(encode_enquiry_reply(127), (std::array<uint8_t, 3>{0x52, 0x9F, 0x06}));
}

// Slaves 0 and 128 have no enquiry and no reply.
TEST(AciEnquiry, RefusesSlave0And128) {
  EXPECT_THROW(encode_enquiry(0), AciError);
  EXPECT_THROW(encode_enquiry(128), AciError);
  EXPECT_THROW(encode_enquiry_reply(0), AciError);
  EXPECT_THROW(encode_enquiry_reply(128), AciError);
}

// ---- Header ----

// The session-opening read (slave 1, read, memtype 0x48, 1 byte) as 13 hand-computed bytes.
TEST(AciHeader, SessionReadVector) {
  const AciHeader header{.slave = 1, .write = false, .memtype = kMemSession, .length = 1};
  // 1 byte: full_blocks = 1 / 128 = 0, last = 1 % 128 = 1. LRC = 0x69 (AciLrc.OfHeader...).
  const std::array<uint8_t, kHeaderSize> expected{0x01, 0x21, 0xFF, 0x00, 0x48, 0x00, 0x01,
                                                  0x00, 0x00, 0x00, 0x00, 0x03, 0x69};
  EXPECT_EQ(encode_header(header), expected);
  EXPECT_EQ(decode_header(expected), header);
}

// A write with offset and segment: little-endian words, and an LRC that wraps (to 0x11).
TEST(AciHeader, WriteWithOffsetAndSegmentVector) {
  const AciHeader header{.slave = 5,
                         .write = true,
                         .memtype = kMemSegment,
                         .offset = 0x1234,
                         .segment = 0xABCD,
                         .length = 300};
  // 300 bytes: full_blocks = 300 / 128 = 2, last = 300 % 128 = 44 = 0x2C.
  // LRC: 0x25 + 0xFF + 0x01 + 0x00 + 0x02 + 0x2C + 0x34 + 0x12 + 0xCD + 0xAB
  //    = 37 + 255 + 1 + 0 + 2 + 44 + 52 + 18 + 205 + 171 = 785 = 3 * 256 + 17 -> 0x11.
  const std::array<uint8_t, kHeaderSize> expected{0x01, 0x25, 0xFF, 0x01, 0x00, 0x02, 0x2C,
                                                  0x34, 0x12, 0xCD, 0xAB, 0x03, 0x11};
  EXPECT_EQ(encode_header(header), expected);
  EXPECT_EQ(decode_header(expected), header);
}

// A multiple of 128 (256 bytes) takes one full block and a last block of 128.
TEST(AciHeader, MultipleOf128Vector) {
  const AciHeader header{.slave = 127, .write = false, .memtype = kMemPointerList, .length = 256};
  // 256 / 128 = 2, 256 % 128 = 0 -> full_blocks = 1, last = 128 = 0x80.
  // LRC: 0x9F + 0xFF + 0x00 + 0x40 + 0x01 + 0x80 = 159 + 255 + 64 + 1 + 128 = 607 -> 607 - 512
  //    = 95 = 0x5F.
  const std::array<uint8_t, kHeaderSize> expected{0x01, 0x9F, 0xFF, 0x00, 0x40, 0x01, 0x80,
                                                  0x00, 0x00, 0x00, 0x00, 0x03, 0x5F};
  EXPECT_EQ(encode_header(header), expected);
  EXPECT_EQ(decode_header(expected), header);
}

// The largest transfer, 32768 bytes, is 255 full blocks and a last one of 128.
TEST(AciHeader, LargestTransfer) {
  const AciHeader header{.slave = 1, .write = true, .length = kMaxTransfer};
  const auto bytes = encode_header(header);
  EXPECT_EQ(bytes[5], 0xFF);  // 32768 / 128 = 256, minus 1 as 32768 % 128 == 0
  EXPECT_EQ(bytes[6], 0x80);
  // 0x21 + 0xFF + 0x01 + 0x00 + 0xFF + 0x80 = 33 + 255 + 1 + 255 + 128 = 672 = 2 * 256 + 160.
  EXPECT_EQ(bytes[12], 0xA0);
  EXPECT_EQ(decode_header(bytes), header);
}

// Headers for lengths 0 and 32769 and for slaves 0 and 128 are refused.
TEST(AciHeader, EncodeRefusesBadLengthAndSlave) {
  EXPECT_THROW(encode_header({.slave = 1, .length = 0}), AciError);
  EXPECT_THROW(encode_header({.slave = 1, .length = kMaxTransfer + 1}), AciError);
  EXPECT_THROW(encode_header({.slave = 0, .length = 1}), AciError);
  EXPECT_THROW(encode_header({.slave = 128, .length = 1}), AciError);
}

// Encoding then decoding gives the header back for many slaves, lengths, directions and addresses.
TEST(AciHeader, RoundTrip) {
  for (int slave : {1, 2, 64, 127}) {
    for (int length : {1, 2, 127, 128, 129, 255, 256, 257, 1000, 32640, 32767, 32768}) {
      for (bool write : {false, true}) {
        const AciHeader header{.slave = slave,
                               .write = write,
                               .memtype = kMemPointerList,
                               .offset = static_cast<uint16_t>(length * 7),
                               .segment = static_cast<uint16_t>(0xF000 + slave),
                               .length = length};
        const auto bytes = encode_header(header);
        EXPECT_EQ(bytes[0], SOH);
        EXPECT_EQ(bytes[2], kHostId);
        EXPECT_EQ(bytes[11], ETX);
        EXPECT_EQ(decode_header(bytes), header) << "slave " << slave << " length " << length;
      }
    }
  }
}

// Changing any one of bytes 1..10 without fixing the LRC is caught, as is a wrong LRC byte.
TEST(AciHeader, CorruptedByteDetected) {
  const AciHeader header{.slave = 1, .write = false, .memtype = kMemSession, .length = 1};
  const auto good = encode_header(header);
  for (int i = 1; i <= 10; ++i) {
    for (uint8_t delta : {0x01, 0x80, 0xFF}) {
      auto bad = good;
      bad[i] = static_cast<uint8_t>(bad[i] + delta);  // the sum changes by delta != 0 mod 256
      EXPECT_THROW(decode_header(bad), AciError) << "byte " << i << " + " << int{delta};
    }
  }
  auto bad_lrc = good;
  bad_lrc[12] = 0x68;  // one less than 0x69
  EXPECT_THROW(decode_header(bad_lrc), AciError);
}

// Framing errors: wrong size, no SOH, no ETX.
TEST(AciHeader, BadFramingRefused) {
  const auto good = encode_header({.slave = 1, .length = 1});
  EXPECT_THROW(decode_header(std::span(good).first(12)), AciError);
  std::vector<uint8_t> longer(good.begin(), good.end());  // 14 bytes
  longer.push_back(0x00);
  EXPECT_THROW(decode_header(longer), AciError);
  EXPECT_THROW(decode_header(std::span<const uint8_t>()), AciError);
  auto no_soh = good;
  no_soh[0] = STX;
  EXPECT_THROW(decode_header(no_soh), AciError);
  auto no_etx = good;
  no_etx[11] = ETB;
  EXPECT_THROW(decode_header(no_etx), AciError);
}

// Fields out of range are refused even when the LRC matches them.
TEST(AciHeader, BadFieldsWithGoodLrcRefused) {
  // Base: 01 21 FF 00 48 00 01 00 00 00 00 03 69; each case changes one byte and the LRC.
  const std::array<uint8_t, kHeaderSize> base{0x01, 0x21, 0xFF, 0x00, 0x48, 0x00, 0x01,
                                              0x00, 0x00, 0x00, 0x00, 0x03, 0x69};
  ASSERT_NO_THROW(decode_header(base));
  auto host = base;  // host id 0xFE: LRC 0x69 - 1 = 0x68
  host[2] = 0xFE;
  host[12] = 0x68;
  EXPECT_THROW(decode_header(host), AciError);
  auto slave0 = base;  // slave byte 0x20 (slave 0): LRC 0x69 - 1 = 0x68
  slave0[1] = 0x20;
  slave0[12] = 0x68;
  EXPECT_THROW(decode_header(slave0), AciError);
  auto slave128 = base;  // slave byte 0xA0 (slave 128): LRC 0x69 + 0x7F = 0xE8
  slave128[1] = 0xA0;
  slave128[12] = 0xE8;
  EXPECT_THROW(decode_header(slave128), AciError);
  auto rw2 = base;  // rw 0x02: LRC 0x69 + 2 = 0x6B
  rw2[3] = 0x02;
  rw2[12] = 0x6B;
  EXPECT_THROW(decode_header(rw2), AciError);
  auto last0 = base;  // last block size 0: LRC 0x69 - 1 = 0x68
  last0[6] = 0x00;
  last0[12] = 0x68;
  EXPECT_THROW(decode_header(last0), AciError);
  auto last129 = base;  // last block size 129 = 0x81: LRC 0x69 + 0x80 = 0xE9
  last129[6] = 0x81;
  last129[12] = 0xE9;
  EXPECT_THROW(decode_header(last129), AciError);
}

// ---- Block layout ----

// No transfer of 0 (or fewer) bytes has a layout.
TEST(AciBlockLayout, ZeroRefused) {
  EXPECT_THROW(block_layout(0), AciError);
  EXPECT_THROW(block_layout(-1), AciError);
}

// 1, 127 and 128 bytes fit one (last) block; 128 by the "last == 0" rule.
TEST(AciBlockLayout, OneBlock) {
  for (int length : {1, 127, 128}) {
    const BlockLayout layout = block_layout(length);
    EXPECT_EQ(layout.full_blocks, 0) << length;
    EXPECT_EQ(layout.last_size, length) << length;
    EXPECT_EQ(layout.total_blocks(), 1) << length;
    EXPECT_EQ(layout.length(), length) << length;
  }
}

// 129 bytes: one full block and a last of 1; 256 bytes: one full block and a last of 128.
TEST(AciBlockLayout, TwoBlocks) {
  const BlockLayout a = block_layout(129);  // 129 / 128 = 1, 129 % 128 = 1
  EXPECT_EQ(a.full_blocks, 1);
  EXPECT_EQ(a.last_size, 1);
  EXPECT_EQ(a.total_blocks(), 2);
  EXPECT_EQ(a.length(), 129);
  const BlockLayout b = block_layout(256);  // 256 / 128 = 2, % = 0 -> 1 and 128
  EXPECT_EQ(b.full_blocks, 1);
  EXPECT_EQ(b.last_size, 128);
  EXPECT_EQ(b.total_blocks(), 2);
  EXPECT_EQ(b.length(), 256);
}

// 32768 bytes is the most: 255 full blocks and a last of 128; 32769 is refused.
TEST(AciBlockLayout, Limit) {
  EXPECT_EQ(kMaxTransfer, 32768);
  const BlockLayout layout = block_layout(32768);
  EXPECT_EQ(layout.full_blocks, 255);
  EXPECT_EQ(layout.last_size, 128);
  EXPECT_EQ(layout.total_blocks(), 256);
  EXPECT_EQ(layout.length(), 32768);
  EXPECT_THROW(block_layout(32769), AciError);
}

// ---- Block frames ----

// A frame holds its data plus STX, terminator and LRC.
TEST(AciBlocks, FrameSize) {
  EXPECT_EQ(block_frame_size(1), 4);
  EXPECT_EQ(block_frame_size(128), 131);
}

// An empty transfer has no frames.
TEST(AciBlocks, EncodeRefusesEmpty) {
  EXPECT_THROW(encode_blocks(std::span<const uint8_t>()), AciError);
}

// One byte 'A': STX 'A' ETX LRC with LRC = 0x41.
TEST(AciBlocks, EncodeOneByte) {
  const std::vector<uint8_t> data{0x41};
  const auto frames = encode_blocks(data);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0], (std::vector<uint8_t>{0x02, 0x41, 0x03, 0x41}));
}

// 127 bytes of 0x02: one last block, LRC 127 * 2 = 254 = 0xFE.
TEST(AciBlocks, Encode127Bytes) {
  const auto frames = encode_blocks(filled(127, 0x02));
  ASSERT_EQ(frames.size(), 1u);
  ASSERT_EQ(frames[0].size(), 130u);
  EXPECT_EQ(frames[0].front(), STX);
  EXPECT_EQ(frames[0][128], ETX);
  EXPECT_EQ(frames[0][129], 0xFE);
  for (int i = 1; i <= 127; ++i) EXPECT_EQ(frames[0][i], 0x02) << i;
}

// 128 bytes counting 0..127: a single block ending ETX (not ETB), LRC 0x1FC0 -> 0xC0.
TEST(AciBlocks, Encode128Bytes) {
  const auto data = counting(128);
  const auto frames = encode_blocks(data);
  ASSERT_EQ(frames.size(), 1u);
  ASSERT_EQ(frames[0].size(), 131u);
  EXPECT_EQ(frames[0][0], STX);
  EXPECT_EQ(frames[0][129], ETX);
  EXPECT_EQ(frames[0][130], 0xC0);
  EXPECT_TRUE(std::equal(data.begin(), data.end(), frames[0].begin() + 1));
}

// 129 bytes of 0x01: STX 128 x 01 ETB 0x80, then STX 01 ETX 01.
TEST(AciBlocks, Encode129Bytes) {
  const auto frames = encode_blocks(filled(129, 0x01));
  ASSERT_EQ(frames.size(), 2u);
  ASSERT_EQ(frames[0].size(), 131u);
  EXPECT_EQ(frames[0][0], STX);
  EXPECT_EQ(frames[0][129], ETB);
  EXPECT_EQ(frames[0][130], 0x80);  // 128 x 1
  EXPECT_EQ(frames[1], (std::vector<uint8_t>{0x02, 0x01, 0x03, 0x01}));
}

// 256 bytes counting 0..255: two blocks of 128, ETB then ETX, LRC 0xC0 each.
TEST(AciBlocks, Encode256Bytes) {
  const auto data = counting(256);
  const auto frames = encode_blocks(data);
  ASSERT_EQ(frames.size(), 2u);
  ASSERT_EQ(frames[0].size(), 131u);
  ASSERT_EQ(frames[1].size(), 131u);
  EXPECT_EQ(frames[0][0], STX);
  EXPECT_EQ(frames[0][129], ETB);
  EXPECT_EQ(frames[0][130], 0xC0);  // 0 + ... + 127 = 8128 = 0x1FC0
  EXPECT_EQ(frames[1][0], STX);
  EXPECT_EQ(frames[1][129], ETX);
  EXPECT_EQ(frames[1][130], 0xC0);  // 128 + ... + 255 = 32640 - 8128 = 24512 = 0x5FC0
  EXPECT_EQ(frames[0][1], 0x00);
  EXPECT_EQ(frames[0][128], 0x7F);
  EXPECT_EQ(frames[1][1], 0x80);
  EXPECT_EQ(frames[1][128], 0xFF);
}

// 32768 bytes of 0x01: 256 blocks of 128, 255 ending ETB and the last ETX, each LRC 0x80.
TEST(AciBlocks, Encode32768Bytes) {
  const auto frames = encode_blocks(filled(32768, 0x01));
  ASSERT_EQ(frames.size(), 256u);
  for (size_t i = 0; i < frames.size(); ++i) {
    ASSERT_EQ(frames[i].size(), 131u) << i;
    EXPECT_EQ(frames[i][0], STX) << i;
    EXPECT_EQ(frames[i][129], i + 1 == frames.size() ? ETX : ETB) << i;
    EXPECT_EQ(frames[i][130], 0x80) << i;
  }
}

// 32769 bytes have no encoding.
TEST(AciBlocks, Encode32769Refused) { EXPECT_THROW(encode_blocks(filled(32769, 0x01)), AciError); }

// Every frame of a transfer decodes back to its data, with `last` only on the final block.
TEST(AciBlocks, DecodeRoundTrip) {
  for (size_t length : {1u, 2u, 127u, 128u, 129u, 255u, 256u, 257u, 1000u, 32768u}) {
    const auto data = counting(length);
    const auto frames = encode_blocks(data);
    std::vector<uint8_t> joined;
    for (size_t i = 0; i < frames.size(); ++i) {
      const Block block = decode_block(frames[i]);
      EXPECT_EQ(block.last, i + 1 == frames.size()) << length << " block " << i;
      joined.insert(joined.end(), block.data.begin(), block.data.end());
    }
    EXPECT_EQ(joined, data) << length;
  }
}

// A hand-built last block decodes: STX 'H' 'i' ETX, LRC 0x48 + 0x69 = 0xB1.
TEST(AciBlocks, DecodeHandBuiltFrame) {
  const std::vector<uint8_t> frame{0x02, 'H', 'i', 0x03, 0xB1};
  const Block block = decode_block(frame);
  EXPECT_EQ(block.data, (std::vector<uint8_t>{'H', 'i'}));
  EXPECT_TRUE(block.last);
}

// A frame whose LRC does not match its data is refused.
TEST(AciBlocks, DecodeRejectsBadLrc) {
  EXPECT_THROW(decode_block(std::vector<uint8_t>{0x02, 'H', 'i', 0x03, 0xB2}), AciError);
  auto frames = encode_blocks(counting(256));
  frames[0][130] ^= 0x01;
  EXPECT_THROW(decode_block(frames[0]), AciError);
  frames[1][5] ^= 0x10;  // data corrupted, LRC left alone
  EXPECT_THROW(decode_block(frames[1]), AciError);
}

// A frame not ending ETB/ETX, not starting STX, or a short block ending ETB is refused.
TEST(AciBlocks, DecodeRejectsWrongTerminator) {
  EXPECT_THROW(decode_block(std::vector<uint8_t>{0x02, 'H', 'i', 0x04, 0xB1}), AciError);  // EOT
  EXPECT_THROW(decode_block(std::vector<uint8_t>{0x02, 'H', 'i', 0x06, 0xB1}), AciError);  // ACK
  // ETB on a 2-byte block: only a full 128-byte block may end ETB.
  EXPECT_THROW(decode_block(std::vector<uint8_t>{0x02, 'H', 'i', 0x17, 0xB1}), AciError);
  EXPECT_THROW(decode_block(std::vector<uint8_t>{0x01, 'H', 'i', 0x03, 0xB1}), AciError);  // SOH
}

// Truncated frames (and an oversized one) are refused.
TEST(AciBlocks, DecodeRejectsTruncatedFrame) {
  EXPECT_THROW(decode_block(std::span<const uint8_t>()), AciError);
  EXPECT_THROW(decode_block(std::vector<uint8_t>{0x02}), AciError);
  EXPECT_THROW(decode_block(std::vector<uint8_t>{0x02, 0x41, 0x03}), AciError);  // LRC missing
  // A full block of 0x01 without its LRC: the second-to-last byte is data (0x01), not ETB.
  const auto frames = encode_blocks(filled(129, 0x01));
  EXPECT_THROW(decode_block(std::span(frames[0]).first(130)), AciError);
  // Without its last data byte and terminator: 129 bytes ending 0x01 0x01.
  EXPECT_THROW(decode_block(std::span(frames[0]).first(129)), AciError);
  std::vector<uint8_t> oversized = frames[0];  // 132 bytes
  oversized.insert(oversized.begin() + 1, 0x01);
  EXPECT_THROW(decode_block(oversized), AciError);
}

// Data holding XON, XOFF, STX, ETX, ETB, ACK and NAK bytes survives the round trip unchanged.
TEST(AciBlocks, ControlBytesInDataSurvive) {
  const std::vector<uint8_t> data{0x11, 0x13, 0x02, 0x03};
  const auto frames = encode_blocks(data);
  ASSERT_EQ(frames.size(), 1u);
  // LRC 0x11 + 0x13 + 0x02 + 0x03 = 17 + 19 + 2 + 3 = 41 = 0x29.
  EXPECT_EQ(frames[0], (std::vector<uint8_t>{0x02, 0x11, 0x13, 0x02, 0x03, 0x03, 0x29}));
  const Block block = decode_block(frames[0]);
  EXPECT_EQ(block.data, data);
  EXPECT_TRUE(block.last);

  // 200 bytes cycling through the control bytes, spanning two blocks.
  const std::array<uint8_t, 8> controls{0x11, 0x13, 0x02, 0x03, 0x17, 0x06, 0x15, 0x04};
  std::vector<uint8_t> many(200);
  for (size_t i = 0; i < many.size(); ++i) many[i] = controls[i % controls.size()];
  const auto many_frames = encode_blocks(many);
  ASSERT_EQ(many_frames.size(), 2u);
  std::vector<uint8_t> joined;
  for (const auto& frame : many_frames) {
    const Block decoded = decode_block(frame);
    joined.insert(joined.end(), decoded.data.begin(), decoded.data.end());
  }
  EXPECT_EQ(joined, many);
}

// ---- byte_name ----

// Control bytes have their names.
TEST(AciByteName, ControlBytes) {
  EXPECT_EQ(byte_name(0x01), "SOH");
  EXPECT_EQ(byte_name(0x02), "STX");
  EXPECT_EQ(byte_name(0x03), "ETX");
  EXPECT_EQ(byte_name(0x04), "EOT");
  EXPECT_EQ(byte_name(0x05), "ENQ");
  EXPECT_EQ(byte_name(0x06), "ACK");
  EXPECT_EQ(byte_name(0x15), "NAK");
  EXPECT_EQ(byte_name(0x17), "ETB");
}

// Printable bytes show hex and the character; others show hex only.
TEST(AciByteName, OtherBytes) {
  EXPECT_EQ(byte_name(0x41), "0x41 'A'");
  EXPECT_EQ(byte_name(0x20), "0x20 ' '");
  EXPECT_EQ(byte_name(0x7E), "0x7E '~'");
  EXPECT_EQ(byte_name(0x00), "0x00");
  EXPECT_EQ(byte_name(0x11), "0x11");
  EXPECT_EQ(byte_name(0x7F), "0x7F");
  EXPECT_EQ(byte_name(0xFF), "0xFF");
}

}  // namespace
}  // namespace sg::arm::aci
