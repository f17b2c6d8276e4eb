// Drives safe decoding (common/safe_decode.hpp) with any bytes, as a hostile bus delivers them:
// the whole input as a message of every type (sg::MessageTypes), directly and through an
// sg::Bus on memq:// subscribed to every type, with the first byte picking the channel the
// input arrives on (so the fingerprint decides, as on a real bus).
// Asserts, beyond not crashing and not allocating beyond the input's own size:
//  - check_wire alone decides: when it accepts, LCM's decoder neither throws nor refuses;
//  - a message that decodes re-encodes to exactly the input bytes (the wire form of a value is
//    unique: lengths, fingerprint and every field are determined by it);
//  - the Bus calls the subscribed type's handler exactly when safe_decode accepts the bytes as
//    that type, and counts every other delivery in decode_errors(); nothing is counted as a
//    handler error.

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "common/bus.hpp"
#include "common/message_types.hpp"
#include "common/safe_decode.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

template <class M>
bool decodes(const uint8_t* data, size_t size) {
  M message{};
  const sg::DecodeResult r = sg::safe_decode(data, static_cast<int64_t>(size), message);
  if (!r) {
    SG_FUZZ_CHECK(!r.reason.starts_with("LCM's decoder"), "%s: check_wire passed, then %s",
                  M::getTypeName(), r.reason.c_str());
    return false;
  }
  const std::vector<uint8_t> again = sg::encode_message(message);
  SG_FUZZ_CHECK(again == std::vector<uint8_t>(data, data + size),
                "%s of %zu bytes re-encodes to %zu other bytes", M::getTypeName(), size,
                again.size());
  return true;
}

/// One channel per type, each subscribed with its type; counts the handlers' calls.
struct Subscribed {
  sg::Bus bus{"memq://"};
  std::vector<std::string> channels;
  int64_t calls = 0;
  Subscribed() {
    sg::for_each_message_type([&]<class M>() {
      channels.push_back(std::string("FUZZ_") + M::getTypeName());
      bus.subscribe<M>(channels.back(), [this](const M&, const sg::ReceiveInfo&) { ++calls; });
    });
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static Subscribed* s = [] {
    spdlog::set_level(spdlog::level::off);
    return new Subscribed;  // lives until exit, as a process's bus does
  }();
  std::vector<bool> accepted;
  sg::for_each_message_type([&]<class M>() { accepted.push_back(decodes<M>(data, size)); });
  if (size == 0) return 0;

  const size_t type = data[0] % s->channels.size();
  const uint64_t errors = s->bus.decode_errors(), calls = s->calls;
  s->bus.publish_raw(s->channels[type], data, static_cast<int>(size));
  SG_FUZZ_CHECK(s->bus.handle(std::chrono::milliseconds(0)), "memq:// delivered nothing");
  SG_FUZZ_CHECK(s->calls - calls == (accepted[type] ? 1 : 0), "handler called %lld times",
                static_cast<long long>(s->calls - calls));
  SG_FUZZ_CHECK(s->bus.decode_errors() - errors == (accepted[type] ? 0 : 1),
                "decode_errors went up by %llu",
                static_cast<unsigned long long>(s->bus.decode_errors() - errors));
  SG_FUZZ_CHECK(s->bus.handler_errors() == 0, "a handler error");
  return 0;
}
