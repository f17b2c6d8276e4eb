#include "common/lcm_datagram.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace sg {
namespace {

uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | p[3];
}
uint16_t be16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }

constexpr size_t kShortHeader = 8, kLongHeader = 20;

/// A channel name for a one-line report: LCM's names may hold any byte, so those outside
/// printable ASCII are written as \xNN.
std::string printable(std::string_view name) {
  std::string out;
  for (const char c : name) {
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += c;
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned char>(c));
      out += hex;
    }
  }
  return out;
}

/// The NUL-terminated channel name at `p` (at most `left` bytes), and its length with the NUL;
/// 0 and `why` set when it is not a name LCM sends.
size_t read_channel(const uint8_t* p, size_t left, std::string_view* channel, std::string* why) {
  const size_t look = std::min(left, kLcmMaxChannel + 1);
  const void* nul = std::memchr(p, 0, look);
  if (nul == nullptr) {
    *why = look > kLcmMaxChannel ? "a channel name longer than LCM's 63 bytes"
                                 : "a channel name without its NUL";
    return 0;
  }
  const size_t length = static_cast<size_t>(static_cast<const uint8_t*>(nul) - p);
  if (length == 0) {
    *why = "an empty channel name";
    return 0;
  }
  *channel = std::string_view(reinterpret_cast<const char*>(p), length);
  return length + 1;
}

std::optional<LcmDatagram> parse_short(const uint8_t* bytes, size_t size, std::string* why) {
  if (size < kShortHeader) {
    *why = "an LC02 datagram of " + std::to_string(size) + " bytes, shorter than its header";
    return std::nullopt;
  }
  LcmDatagram d;
  d.seqno = be32(bytes + 4);
  const size_t name = read_channel(bytes + kShortHeader, size - kShortHeader, &d.channel, why);
  if (name == 0) return std::nullopt;
  d.data = bytes + kShortHeader + name;
  d.size = size - kShortHeader - name;
  d.message_size = static_cast<uint32_t>(d.size);
  return d;
}

std::optional<LcmDatagram> parse_long(const uint8_t* bytes, size_t size, std::string* why) {
  if (size < kLongHeader) {
    *why = "an LC03 datagram of " + std::to_string(size) + " bytes, shorter than its header";
    return std::nullopt;
  }
  LcmDatagram d;
  d.fragment = true;
  d.seqno = be32(bytes + 4);
  d.message_size = be32(bytes + 8);
  d.offset = be32(bytes + 12);
  d.fragment_no = be16(bytes + 16);
  d.fragments = be16(bytes + 18);
  if (d.fragment_no >= d.fragments) {
    *why =
        "an LC03 fragment " + std::to_string(d.fragment_no) + " of " + std::to_string(d.fragments);
    return std::nullopt;
  }
  size_t name = 0;
  if (d.fragment_no == 0) {
    name = read_channel(bytes + kLongHeader, size - kLongHeader, &d.channel, why);
    if (name == 0) return std::nullopt;
  }
  d.data = bytes + kLongHeader + name;
  d.size = size - kLongHeader - name;
  if (uint64_t{d.offset} + d.size > d.message_size) {
    *why = "an LC03 fragment with bytes " + std::to_string(d.offset) + ".." +
           std::to_string(uint64_t{d.offset} + d.size) + " of a " + std::to_string(d.message_size) +
           "-byte message";
    return std::nullopt;
  }
  return d;
}

}  // namespace

std::optional<LcmDatagram> parse_lcm_datagram(const uint8_t* bytes, size_t size, std::string* why) {
  if (size < 4) {
    *why = "a datagram of " + std::to_string(size) + " bytes, shorter than LCM's magic number";
    return std::nullopt;
  }
  const uint32_t magic = be32(bytes);
  if (magic == kLcmMagicShort) return parse_short(bytes, size, why);
  if (magic == kLcmMagicLong) return parse_long(bytes, size, why);
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%08x", magic);
  *why = std::string("not an LCM datagram (magic ") + hex + ")";
  return std::nullopt;
}

/// One message in assembly, or a slot whose buffer waits for the next.
struct LcmDatagramAssembler::Assembly {
  enum class State { kIdle, kAssembling, kComplete } state = State::kIdle;
  uint64_t sender = 0, last_used = 0;
  uint32_t seqno = 0, size = 0, filled = 0;
  uint16_t next_fragment = 0, fragments = 0;
  std::string channel;
  std::unique_ptr<uint8_t[]> buffer;  // default-initialised: pages committed as they are written
  size_t capacity = 0;

  /// "CAMERA_LEFT: message 17 (921654 bytes) dropped: " + why.
  std::string lost(const std::string& why) const {
    return printable(channel) + ": message " + std::to_string(seqno) + " (" + std::to_string(size) +
           " bytes, " + std::to_string(next_fragment) + " of " + std::to_string(fragments) +
           " fragments) dropped: " + why;
  }
};

LcmDatagramAssembler::LcmDatagramAssembler(Limits limits) : limits_(limits) {
  limits_.max_senders = std::max<size_t>(limits_.max_senders, 1);
  limits_.max_held = std::max({limits_.max_held, limits_.max_message, size_t{1}});  // room for one
}

size_t LcmDatagramAssembler::held() const {
  size_t bytes = 0;
  for (const auto& a : assemblies_) bytes += a->capacity;
  return bytes;
}

/// Gives `slot` a buffer of at least `size` bytes within max_held: idle buffers are freed first,
/// then the least recently fed assemblies dropped.
void LcmDatagramAssembler::make_room(Assembly& slot, size_t size, const Refused& refused) {
  const size_t wanted = std::max<size_t>(size, 1);
  if (slot.capacity >= wanted && slot.capacity <= 4 * wanted + (size_t{1} << 20)) return;
  slot.buffer.reset(), slot.capacity = 0;
  while (held() + wanted > limits_.max_held) {
    Assembly* victim = nullptr;
    for (auto& a : assemblies_) {
      if (a.get() == &slot || a->capacity == 0) continue;
      const bool idle = a->state != Assembly::State::kAssembling;
      const bool victim_idle = victim && victim->state != Assembly::State::kAssembling;
      if (!victim || (idle && !victim_idle) ||
          (idle == victim_idle && a->last_used < victim->last_used))
        victim = a.get();
    }
    if (victim->state == Assembly::State::kAssembling)
      refused(victim->lost("the buffers held would pass " + std::to_string(limits_.max_held) +
                           " bytes"));
    victim->state = Assembly::State::kIdle;
    victim->buffer.reset(), victim->capacity = 0;
  }
  slot.buffer.reset(new uint8_t[wanted]);
  slot.capacity = wanted;
}
LcmDatagramAssembler::~LcmDatagramAssembler() = default;

size_t LcmDatagramAssembler::in_assembly() const {
  return static_cast<size_t>(std::count_if(assemblies_.begin(), assemblies_.end(), [](auto& a) {
    return a->state == Assembly::State::kAssembling;
  }));
}

LcmDatagramAssembler::Assembly* LcmDatagramAssembler::assembly_of(uint64_t sender) {
  for (auto& a : assemblies_)
    if (a->state == Assembly::State::kAssembling && a->sender == sender) return a.get();
  return nullptr;
}

/// A free slot, a new one within the bound, or the least recently fed assembly's.
LcmDatagramAssembler::Assembly& LcmDatagramAssembler::start(uint64_t sender) {
  Assembly* slot = nullptr;
  for (auto& a : assemblies_)
    if (a->state != Assembly::State::kAssembling && (!slot || a->capacity > slot->capacity))
      slot = a.get();
  if (slot == nullptr && assemblies_.size() < limits_.max_senders) {
    assemblies_.push_back(std::make_unique<Assembly>());
    slot = assemblies_.back().get();
  }
  if (slot == nullptr) {
    slot = std::min_element(assemblies_.begin(), assemblies_.end(), [](auto& a, auto& b) {
             return a->last_used < b->last_used;
           })->get();
  }
  slot->sender = sender;
  return *slot;
}

std::optional<LcmMessage> LcmDatagramAssembler::add(uint64_t sender, const uint8_t* bytes,
                                                    size_t size, const Wanted& wanted,
                                                    const Refused& refused) {
  for (auto& a : assemblies_)  // the message returned last is no longer needed
    if (a->state == Assembly::State::kComplete) a->state = Assembly::State::kIdle;
  std::string why;
  const std::optional<LcmDatagram> d = parse_lcm_datagram(bytes, size, &why);
  if (!d) {
    refused(why);
    return std::nullopt;
  }
  Assembly* a = assembly_of(sender);
  if (a != nullptr && (!d->fragment || d->seqno != a->seqno || d->fragment_no == 0)) {
    // LCM sends a message's fragments before the next message: this one's rest was lost.
    refused(a->lost(d->fragment_no == 0 && d->fragment && d->seqno == a->seqno
                        ? "its first fragment came again"
                        : "the sender's next message came before its last fragment"));
    a->state = Assembly::State::kIdle;
    a = nullptr;
  }
  if ((!d->fragment || d->fragment_no == 0) && !wanted(d->channel)) return std::nullopt;
  if ((!d->fragment || d->fragment_no == 0) && d->message_size > limits_.max_message) {
    refused(printable(d->channel) + ": a " + std::to_string(d->message_size) +
            "-byte message, above the bound of " + std::to_string(limits_.max_message));
    return std::nullopt;
  }
  if (!d->fragment) return LcmMessage{d->channel, d->data, d->size};
  if (d->fragment_no == 0) {
    a = &start(sender);
    if (a->state == Assembly::State::kAssembling)
      refused(a->lost("more than " + std::to_string(limits_.max_senders) +
                      " senders' messages in assembly at once"));
    a->state = Assembly::State::kAssembling;
    a->seqno = d->seqno, a->size = d->message_size, a->filled = 0;
    a->next_fragment = 0, a->fragments = d->fragments;
    a->channel.assign(d->channel);
    make_room(*a, a->size, refused);
  }
  if (a == nullptr) return std::nullopt;  // a fragment of a message not assembled here
  a->last_used = ++clock_;
  return continue_fragment(*a, *d, refused);
}

std::optional<LcmMessage> LcmDatagramAssembler::continue_fragment(Assembly& a, const LcmDatagram& d,
                                                                  const Refused& refused) {
  std::string why;
  if (d.fragment_no != a.next_fragment)
    why = "fragment " + std::to_string(d.fragment_no) + " came where " +
          std::to_string(a.next_fragment) + " was due";
  else if (d.fragments != a.fragments || d.message_size != a.size)
    why = "fragment " + std::to_string(d.fragment_no) + " claims another message's size";
  else if (d.offset != a.filled)
    why = "fragment " + std::to_string(d.fragment_no) + " starts at byte " +
          std::to_string(d.offset) + ", not " + std::to_string(a.filled);
  else if (d.fragment_no + 1 == a.fragments && a.filled + d.size != a.size)
    why = "its fragments hold " + std::to_string(a.filled + d.size) + " bytes";
  if (!why.empty()) {
    refused(a.lost(why));
    a.state = Assembly::State::kIdle;
    return std::nullopt;
  }
  if (d.size > 0) std::memcpy(a.buffer.get() + a.filled, d.data, d.size);
  a.filled += static_cast<uint32_t>(d.size);
  if (++a.next_fragment < a.fragments) return std::nullopt;
  a.state = Assembly::State::kComplete;
  return LcmMessage{a.channel, a.buffer.get(), a.size};
}

}  // namespace sg
