// Drives the check every guarded bus runs on every message before any handler (auth/data_auth.hpp,
// DataGuard::check, and common/vouch_trailer.hpp's parser under it) with any bytes: up to 8
// records (fuzz/vouched_messages.hpp: a selector byte for the channel and the reader's clock, a
// 2-byte length, the bytes), each checked by one sg-grasp guard per input with a fixed key. The
// committed seeds are forecasts and an ARM_STATUS vouched for with that key, one vouched for by a
// process not allowed on its channel, one under another key, a replay, and unvouched bytes.
// Asserts, beyond never crashing and check never throwing:
//  - a message is accepted only if its channel, its LCM encoding, its sender, instance and
//    counter and the tag for sg-grasp are those of one of the vouched messages (libFuzzer cannot
//    forge a Poly1305 tag, so anything else accepted is a hole); the other readers' tags are
//    theirs to check, and changing one makes no message believed that was not vouched for;
//  - accepted messages of one (sender, instance, channel) have strictly increasing counters,
//    each within 30 s of the reader's clock; the payload size is what the trailer leaves;
//  - kUnsigned is exactly "no magic at the end", kMalformed exactly a parse that fails;
//  - a trailer that parses writes back to the same bytes (append_vouch_trailer);
//  - the guard's counts add up to the messages it was given.

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "auth/data_auth.hpp"
#include "common/vouch_trailer.hpp"
#include "fuzz/fuzz_support.hpp"
#include "fuzz/vouched_messages.hpp"

namespace {

/// What sg-grasp's tag vouches for in a message on `channel`: the encoding, the sender, its run,
/// the counter, and the tag itself.
using Vouching = std::tuple<int, std::vector<uint8_t>, std::string, uint32_t, int64_t,
                            std::array<uint8_t, sg::kVouchTagSize>>;
using Vouched = std::set<Vouching>;

/// `bytes`' Vouching as sg-grasp reads it (a zero tag when it has none).
Vouching vouching_of(int channel, const std::vector<uint8_t>& bytes) {
  const sg::TrailerParse p = sg::parse_vouch_trailer(bytes.data(), bytes.size());
  std::array<uint8_t, sg::kVouchTagSize> tag{};
  for (const sg::VouchTag& t : p.trailer.tags)
    if (t.reader == "sg-grasp") tag = t.tag;
  return {channel,
          std::vector<uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(p.payload_size)),
          p.trailer.sender,
          p.trailer.instance,
          p.trailer.counter,
          tag};
}

/// The vouched messages; first checks the check is not vacuous: a fresh guard accepts each, and
/// refuses the not-allowed and other-key ones as such.
const Vouched& vouched_set(const sg::auth::Credentials& grasp) {
  static const Vouched set = [&] {
    Vouched s;
    for (const sg::fuzz::VouchedMessage& m : sg::fuzz::vouched_messages()) {
      sg::auth::DataGuard fresh(grasp, {}, sg::system_clock(), 9);
      const sg::GuardResult r = fresh.check(sg::fuzz::kVouchChannels[m.channel], m.bytes.data(),
                                            m.bytes.size(), sg::fuzz::kNow);
      SG_FUZZ_CHECK(r.accepted(), "a vouched seed is %s: %s", sg::to_string(r.verdict),
                    r.reason.c_str());
      s.insert(vouching_of(m.channel, m.bytes));
    }
    const auto bad = sg::fuzz::not_allowed_and_wrong_key();
    sg::auth::DataGuard fresh(grasp, {}, sg::system_clock(), 9);
    SG_FUZZ_CHECK(fresh.check(sg::fuzz::kVouchChannels[0], bad[0].bytes.data(), bad[0].bytes.size(),
                              sg::fuzz::kNow)
                              .verdict == sg::GuardVerdict::kNotAllowed &&
                      fresh.check(sg::fuzz::kVouchChannels[0], bad[1].bytes.data(),
                                  bad[1].bytes.size(), sg::fuzz::kNow)
                              .verdict == sg::GuardVerdict::kBadTag,
                  "the not-allowed or other-key message is not refused as such");
    return s;
  }();
  return set;
}

/// The trailer's own properties: the verdict agrees with the parse; a parse writes back.
void check_trailer(const std::vector<uint8_t>& bytes, const sg::GuardResult& r) {
  const sg::TrailerParse p = sg::parse_vouch_trailer(bytes.data(), bytes.size());
  SG_FUZZ_CHECK((p.kind == sg::TrailerParse::kNone) == (r.verdict == sg::GuardVerdict::kUnsigned),
                "verdict %s for a parse of kind %d", sg::to_string(r.verdict), p.kind);
  SG_FUZZ_CHECK(
      (p.kind == sg::TrailerParse::kMalformed) == (r.verdict == sg::GuardVerdict::kMalformed),
      "verdict %s for a parse of kind %d", sg::to_string(r.verdict), p.kind);
  SG_FUZZ_CHECK(p.payload_size <= bytes.size(), "payload %zu of %zu bytes", p.payload_size,
                bytes.size());
  if (p.kind != sg::TrailerParse::kFound) return;
  std::vector<uint8_t> again(bytes.begin(), bytes.begin() + static_cast<long>(p.payload_size));
  sg::append_vouch_trailer(again, p.trailer);
  SG_FUZZ_CHECK(again == bytes, "a parsed trailer writes back to %zu other bytes", again.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const sg::auth::Credentials grasp =
      sg::auth::credentials_from_lab_key(sg::fuzz::fuzz_key(), "sg-grasp");
  const Vouched& vouched = vouched_set(grasp);
  sg::auth::DataGuard guard(grasp, {}, sg::system_clock(), 9);
  std::map<std::tuple<std::string, uint32_t, int>, int64_t> last;
  int64_t given = 0;
  size_t at = 0;
  for (size_t record = 0; record < sg::fuzz::kMaxRecords && at + 3 <= size; ++record) {
    const uint8_t selector = data[at];
    const size_t length =
        std::min<size_t>((size_t{data[at + 1]} << 8) | data[at + 2], size - at - 3);
    const std::vector<uint8_t> bytes(data + at + 3, data + at + 3 + length);
    at += 3 + length;
    const int channel = selector & 3;
    const int64_t now = sg::fuzz::kNow + (int64_t{selector >> 2} - 32) * 2'000'000;
    const sg::GuardResult r =
        guard.check(sg::fuzz::kVouchChannels[channel], bytes.data(), bytes.size(), now);
    ++given;
    check_trailer(bytes, r);
    SG_FUZZ_CHECK(r.accepted() == r.reason.empty(), "reason '%s' with %s", r.reason.c_str(),
                  sg::to_string(r.verdict));
    if (!r.accepted()) continue;
    SG_FUZZ_CHECK(vouched.count(vouching_of(channel, bytes)) == 1,
                  "accepted %zu bytes on '%s' from '%s' that nobody vouched for", bytes.size(),
                  sg::fuzz::kVouchChannels[channel].c_str(), r.sender.c_str());
    const sg::TrailerParse p = sg::parse_vouch_trailer(bytes.data(), bytes.size());
    SG_FUZZ_CHECK(r.payload_size == p.payload_size, "payload %zu, the trailer leaves %zu",
                  r.payload_size, p.payload_size);
    const auto stream = std::make_tuple(p.trailer.sender, p.trailer.instance, channel);
    const auto seen = last.find(stream);
    SG_FUZZ_CHECK(seen == last.end() || p.trailer.counter > seen->second,
                  "replay accepted: counter %lld after %lld",
                  static_cast<long long>(p.trailer.counter), static_cast<long long>(seen->second));
    SG_FUZZ_CHECK(p.trailer.counter >= now - 30'000'000 && p.trailer.counter <= now + 30'000'000,
                  "stale accepted: counter %lld at %lld", static_cast<long long>(p.trailer.counter),
                  static_cast<long long>(now));
    last[stream] = p.trailer.counter;
  }
  int64_t counted = 0;
  for (int v = 0; v < sg::kGuardVerdicts; ++v)
    counted += guard.count(static_cast<sg::GuardVerdict>(v));
  SG_FUZZ_CHECK(counted == given, "%lld verdicts for %lld messages",
                static_cast<long long>(counted), static_cast<long long>(given));
  return 0;
}
