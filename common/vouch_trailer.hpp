#pragma once

/// The vouching trailer: what a publisher appends to every LCM message it sends so that each
/// reader the lab names can tell who sent it, that nobody changed it, and that it is new
/// (docs/security.md, "Every datum vouched for"). It rides *after* the LCM encoding, so the
/// message's type is unchanged: lcm-spy and every LCM decoder read the message and ignore the
/// bytes that follow; lcm-logger records them with it. Layout, all integers big-endian:
///
///     LCM encoding (fingerprint and fields)
///     u8 sender length | sender (1..32 bytes of [A-Za-z0-9._@:-])
///     u32 instance     | i64 counter
///     u8 tag count (0..32) | per tag: u8 reader length | reader | 16-byte tag
///     u16 trailer length (from the sender length byte to the end, magic included)
///     "SGv1"
///
/// The trailer is found from the end: the last four bytes are the magic, the two before them
/// its length; every length inside it is bounded by the bytes there, and the fields must end
/// exactly at the length word. This file only parses and writes the layout (plain C++, no
/// cryptography); auth/data_auth.hpp makes and checks the tags.
///
///     sg::VouchTrailer t{"sg-predictor", 7, 1765000000000000, {{"sg-grasp", tag}}};
///     sg::append_vouch_trailer(bytes, t);                 // bytes: an LCM encoding
///     const sg::TrailerParse p = sg::parse_vouch_trailer(bytes.data(), bytes.size());
///     // p.kind == kFound, p.payload_size == the encoding's size, p.trailer == t

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace sg {

inline constexpr std::size_t kVouchTagSize = 16;  ///< bytes of one reader's tag
inline constexpr std::size_t kVouchMaxName = 32;  ///< bytes of a sender's or reader's name
inline constexpr std::size_t kVouchMaxTags = 32;  ///< readers one message is vouched for
inline constexpr char kVouchMagic[5] = "SGv1";

/// One reader's proof: a tag only that reader (and the sender) can make.
struct VouchTag {
  std::string reader;
  std::array<uint8_t, kVouchTagSize> tag{};
  bool operator==(const VouchTag&) const = default;
};

/// Who vouches for a message, which of its runs (a random number drawn at start, so two
/// processes of one name keep separate counters), its counter (strictly increasing per
/// instance and channel), and the tags for its readers.
struct VouchTrailer {
  std::string sender;
  uint32_t instance = 0;
  int64_t counter = 0;
  std::vector<VouchTag> tags;
  bool operator==(const VouchTrailer&) const = default;
};

/// What the end of a message holds.
struct TrailerParse {
  enum Kind { kNone, kMalformed, kFound } kind = kNone;
  std::size_t payload_size = 0;  ///< the LCM encoding's bytes (all of them when kNone)
  VouchTrailer trailer;          ///< when kFound
  std::string why;               ///< when kMalformed: one line
};

/// True for a name a trailer may carry: 1..32 bytes of letters, digits and . _ @ : -
bool valid_vouch_name(std::string_view name);

/// Reads the trailer of `size` bytes at `data`: kNone when they do not end in the magic (an
/// unvouched message: payload_size = size), kMalformed when they end in it but what precedes is
/// not a whole trailer, kFound otherwise. Never reads outside the bytes.
TrailerParse parse_vouch_trailer(const uint8_t* data, std::size_t size);

/// The bytes of `data` that are the LCM encoding: all but a well-formed trailer.
std::size_t vouched_payload_size(const uint8_t* data, std::size_t size);

/// Appends `trailer` to `bytes`. Throws std::invalid_argument for a name that is not
/// valid_vouch_name() or more than kVouchMaxTags tags.
void append_vouch_trailer(std::vector<uint8_t>& bytes, const VouchTrailer& trailer);

/// The bytes append_vouch_trailer() adds for a trailer with these names.
std::size_t vouch_trailer_size(std::string_view sender, const std::vector<VouchTag>& tags);

}  // namespace sg
