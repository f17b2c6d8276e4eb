// Drives LCM's UDP wire format as read without LCM (common/lcm_datagram.hpp, what sg::Bus reads
// on its own socket for subscribe_direct) with any datagrams from any senders. The input is a
// sequence of records: a sender byte, a big-endian uint16 length, that many bytes of a datagram
// (the last record takes what is left). Small bounds (a 4 KiB message, three senders, 6,000
// bytes held) so that the fuzzer reaches them.
// Asserts, beyond not crashing and not reading or allocating out of bounds:
//  - every message that comes out is on a wanted channel and within the bound;
//  - a short (LC02) datagram on a wanted channel within the bound comes out as exactly its
//    payload;
//  - no more messages are in assembly than the bound on senders, no more bytes held than its bound;
//  - every refusal is one non-empty line.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>

#include "common/lcm_datagram.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

constexpr size_t kMaxMessage = 4096, kMaxSenders = 3, kMaxHeld = 6000;

bool wanted(std::string_view channel) { return !channel.empty() && channel[0] == 'C'; }

void check_refusal(const std::string& why) {
  SG_FUZZ_CHECK(!why.empty() && why.find('\n') == std::string::npos, "refusal '%s'", why.c_str());
}

/// Feeds one datagram; checks what comes out.
void feed(sg::LcmDatagramAssembler& assembler, uint64_t sender, const uint8_t* d, size_t n) {
  const auto message = assembler.add(sender, d, n, wanted, check_refusal);
  SG_FUZZ_CHECK(assembler.in_assembly() <= kMaxSenders, "%zu in assembly", assembler.in_assembly());
  std::string why;
  const auto parsed = sg::parse_lcm_datagram(d, n, &why);
  if (!message) {
    SG_FUZZ_CHECK(
        !(parsed && !parsed->fragment && wanted(parsed->channel) && parsed->size <= kMaxMessage),
        "a wanted short message within the bound did not come out");
    return;
  }
  SG_FUZZ_CHECK(parsed, "a message came out of a datagram the parser refuses: %s", why.c_str());
  SG_FUZZ_CHECK(wanted(message->channel), "a message on an unwanted channel");
  SG_FUZZ_CHECK(message->size <= kMaxMessage, "a %zu-byte message", message->size);
  if (!parsed->fragment) {
    SG_FUZZ_CHECK(
        message->size == parsed->size &&
            (message->size == 0 || std::memcmp(message->data, parsed->data, message->size) == 0),
        "a short message is not its payload");
  }
  if (message->size > 0) {  // every byte readable (ASan checks), none uninitialised by design
    volatile uint8_t sum = 0;
    for (size_t i = 0; i < message->size; ++i) sum = static_cast<uint8_t>(sum + message->data[i]);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  sg::LcmDatagramAssembler assembler(
      sg::LcmDatagramAssembler::Limits{kMaxMessage, kMaxSenders, kMaxHeld});
  size_t at = 0;
  while (at + 3 <= size) {
    const uint64_t sender = data[at] % 5;
    size_t length = (size_t{data[at + 1]} << 8) | data[at + 2];
    at += 3;
    length = std::min(length, size - at);
    feed(assembler, sender, data + at, length);
    at += length;
  }
  return 0;
}
