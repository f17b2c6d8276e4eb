#include "common/vouch_trailer.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace sg {
namespace {

constexpr std::size_t kMagicSize = 4;
constexpr std::size_t kEnd = 2 + kMagicSize;  // the length word and the magic
/// The smallest trailer: a 1-byte sender, instance, counter, no tags, the end.
constexpr std::size_t kMinTrailer = 1 + 1 + 4 + 8 + 1 + kEnd;

/// Reads big-endian fields from a bounded span; every read checks what is left.
class Reader {
 public:
  Reader(const uint8_t* p, std::size_t n) : p_(p), n_(n) {}
  bool u8(uint8_t& v) {
    if (n_ < 1) return false;
    v = *p_++;
    --n_;
    return true;
  }
  bool bytes(std::size_t k, const uint8_t*& out) {
    if (n_ < k) return false;
    out = p_;
    p_ += k;
    n_ -= k;
    return true;
  }
  bool be(std::size_t k, uint64_t& v) {
    const uint8_t* b = nullptr;
    if (!bytes(k, b)) return false;
    v = 0;
    for (std::size_t i = 0; i < k; ++i) v = (v << 8) | b[i];
    return true;
  }
  bool name(std::string& out) {
    uint8_t len = 0;
    const uint8_t* b = nullptr;
    if (!u8(len) || !bytes(len, b)) return false;
    out.assign(reinterpret_cast<const char*>(b), len);
    return valid_vouch_name(out);
  }
  std::size_t left() const { return n_; }

 private:
  const uint8_t* p_;
  std::size_t n_;
};

void put_be(std::vector<uint8_t>& out, uint64_t v, std::size_t k) {
  for (std::size_t i = 0; i < k; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * (k - 1 - i))));
}

void put_name(std::vector<uint8_t>& out, const std::string& name) {
  if (!valid_vouch_name(name))
    throw std::invalid_argument("not a name a vouching trailer can carry: '" + name + "'");
  out.push_back(static_cast<uint8_t>(name.size()));
  out.insert(out.end(), name.begin(), name.end());
}

TrailerParse malformed(std::size_t size, std::string why) {
  TrailerParse p;
  p.kind = TrailerParse::kMalformed;
  p.payload_size = size;
  p.why = std::move(why);
  return p;
}

}  // namespace

bool valid_vouch_name(std::string_view name) {
  if (name.empty() || name.size() > kVouchMaxName) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
           c == '_' || c == '@' || c == ':' || c == '-';
  });
}

TrailerParse parse_vouch_trailer(const uint8_t* data, std::size_t size) {
  TrailerParse none;
  none.payload_size = size;
  if (size < kMagicSize || std::memcmp(data + size - kMagicSize, kVouchMagic, kMagicSize) != 0)
    return none;
  if (size < kMinTrailer) return malformed(size, "a vouching trailer's magic, but too short");
  const std::size_t length = (std::size_t{data[size - kEnd]} << 8) | data[size - kEnd + 1];
  if (length < kMinTrailer || length > size)
    return malformed(size, "vouching trailer length " + std::to_string(length) + " of a " +
                               std::to_string(size) + "-byte message");
  TrailerParse p;
  p.kind = TrailerParse::kFound;
  p.payload_size = size - length;
  Reader r(data + p.payload_size, length - kEnd);
  uint64_t instance = 0, counter = 0;
  uint8_t tags = 0;
  if (!r.name(p.trailer.sender) || !r.be(4, instance) || !r.be(8, counter) || !r.u8(tags))
    return malformed(size, "vouching trailer: a bad sender, instance or counter");
  if (tags > kVouchMaxTags)
    return malformed(size, "vouching trailer: " + std::to_string(tags) + " tags (at most 32)");
  p.trailer.instance = static_cast<uint32_t>(instance);
  p.trailer.counter = static_cast<int64_t>(counter);
  p.trailer.tags.resize(tags);
  for (VouchTag& t : p.trailer.tags) {
    const uint8_t* tag = nullptr;
    if (!r.name(t.reader) || !r.bytes(kVouchTagSize, tag))
      return malformed(size, "vouching trailer: a bad reader name or a cut tag");
    std::memcpy(t.tag.data(), tag, kVouchTagSize);
  }
  if (r.left() != 0)
    return malformed(size, "vouching trailer: " + std::to_string(r.left()) + " bytes left over");
  return p;
}

std::size_t vouched_payload_size(const uint8_t* data, std::size_t size) {
  const TrailerParse p = parse_vouch_trailer(data, size);
  return p.kind == TrailerParse::kFound ? p.payload_size : size;
}

std::size_t vouch_trailer_size(std::string_view sender, const std::vector<VouchTag>& tags) {
  std::size_t n = 1 + sender.size() + 4 + 8 + 1 + kEnd;
  for (const VouchTag& t : tags) n += 1 + t.reader.size() + kVouchTagSize;
  return n;
}

void append_vouch_trailer(std::vector<uint8_t>& bytes, const VouchTrailer& trailer) {
  if (trailer.tags.size() > kVouchMaxTags)
    throw std::invalid_argument("a vouching trailer holds at most 32 tags");
  const std::size_t start = bytes.size();
  put_name(bytes, trailer.sender);
  put_be(bytes, trailer.instance, 4);
  put_be(bytes, static_cast<uint64_t>(trailer.counter), 8);
  bytes.push_back(static_cast<uint8_t>(trailer.tags.size()));
  for (const VouchTag& t : trailer.tags) {
    put_name(bytes, t.reader);
    bytes.insert(bytes.end(), t.tag.begin(), t.tag.end());
  }
  put_be(bytes, bytes.size() - start + kEnd, 2);
  bytes.insert(bytes.end(), kVouchMagic, kVouchMagic + kMagicSize);
}

}  // namespace sg
