// Drives the signed-command check (auth/command_auth.hpp, CommandVerifier: what sg-arm-driver
// and sg-grasp run on every ARM_COMMAND and GRASP_COMMAND) with any bytes: up to 8 records
// (fuzz/signed_commands.hpp: a selector byte for the type, the channel and the receiver's
// clock, a 2-byte length, the bytes), each decoded through sg::safe_decode as arm_cmd_t or
// grasp_command_t as the bus delivers it, then verified by one CommandVerifier per input with a
// fixed key. The committed seeds are commands signed with that key, unsigned, signed with
// another key, on the wrong channel, and replayed.
// Asserts, beyond never crashing and verify never throwing:
//  - a command is accepted only if it is, to the byte and on its channel, one of the commands
//    signed with the key (libFuzzer cannot forge an HMAC-SHA-512-256 tag, so every other input
//    that the verifier accepts is a hole in the check);
//  - accepted commands of one sender have strictly increasing counters, each within 30 s of
//    the receiver's clock (no replay, no stale command);
//  - a zero tag is kUnsigned, and kUnsigned is only a zero tag;
//  - the verifier's counts add up to the commands it was given.

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "auth/command_auth.hpp"
#include "common/safe_decode.hpp"
#include "fuzz/fuzz_support.hpp"
#include "fuzz/signed_commands.hpp"

namespace auth = sg::auth;

namespace {

using Signed = std::set<std::pair<int, std::vector<uint8_t>>>;  // (channel, bytes)

template <class M>
auth::Verdict verdict(const auth::LabKey& key, const sg::fuzz::SignedCommand& c) {
  M message{};
  SG_FUZZ_CHECK(sg::safe_decode(c.bytes.data(), static_cast<int64_t>(c.bytes.size()), message),
                "a seed command does not decode");
  auth::CommandVerifier verifier(key);
  return verifier.verify(sg::fuzz::kChannels[c.channel], message, sg::fuzz::kNow).verdict;
}

/// The signed commands; first checks that the check is not vacuous: each is accepted by a fresh
/// verifier, and the unsigned and other-key ones are refused.
const Signed& signed_set(const auth::LabKey& key) {
  static const Signed set = [&] {
    Signed s;
    for (const sg::fuzz::SignedCommand& c : sg::fuzz::signed_commands()) {
      const auth::Verdict v = c.grasp ? verdict<stereograsp::grasp_command_t>(key, c)
                                      : verdict<stereograsp::arm_cmd_t>(key, c);
      SG_FUZZ_CHECK(v == auth::Verdict::kAccepted, "a signed command is %s", auth::to_string(v));
      s.insert({c.channel, c.bytes});
    }
    const auto bad = sg::fuzz::unsigned_and_wrong_key();
    SG_FUZZ_CHECK(verdict<stereograsp::arm_cmd_t>(key, bad[0]) == auth::Verdict::kUnsigned &&
                      verdict<stereograsp::arm_cmd_t>(key, bad[1]) == auth::Verdict::kBadTag,
                  "the unsigned or other-key command is not refused as such");
    return s;
  }();
  return set;
}

/// What the input's verifier was given and accepted so far: each sender's last counter.
struct Accepted {
  std::map<std::string, int64_t> last;
  int64_t verified = 0;  ///< commands given to the verifier (those safe_decode let through)
};

template <class M>
void check_one(const auth::LabKey& key, auth::CommandVerifier& verifier, int channel, int64_t now,
               const std::vector<uint8_t>& bytes, Accepted& accepted) {
  M message{};
  if (!sg::safe_decode(bytes.data(), static_cast<int64_t>(bytes.size()), message)) return;
  ++accepted.verified;
  const auth::Verification v = verifier.verify(sg::fuzz::kChannels[channel], message, now);
  const bool zero_tag = std::all_of(std::begin(message.auth_tag), std::end(message.auth_tag),
                                    [](uint8_t b) { return b == 0; });
  SG_FUZZ_CHECK(zero_tag == (v.verdict == auth::Verdict::kUnsigned), "%s: verdict %s",
                M::getTypeName(), auth::to_string(v.verdict));
  SG_FUZZ_CHECK(v.accepted() == v.reason.empty(), "reason '%s' with %s", v.reason.c_str(),
                auth::to_string(v.verdict));
  if (!v.accepted()) return;
  // safe_decode's bytes re-encode to the input (safe_decode_fuzz), so the input is the message.
  SG_FUZZ_CHECK(signed_set(key).count({channel, bytes}) == 1,
                "accepted a %s of %zu bytes on '%s' from '%s' that was never signed",
                M::getTypeName(), bytes.size(), sg::fuzz::kChannels[channel].c_str(),
                message.sender.c_str());
  const auto last = accepted.last.find(message.sender);
  SG_FUZZ_CHECK(last == accepted.last.end() || message.auth_counter > last->second,
                "replay accepted: counter %lld after %lld",
                static_cast<long long>(message.auth_counter), static_cast<long long>(last->second));
  SG_FUZZ_CHECK(
      message.auth_counter >= now - 30'000'000 && message.auth_counter <= now + 30'000'000,
      "stale accepted: counter %lld at %lld", static_cast<long long>(message.auth_counter),
      static_cast<long long>(now));
  accepted.last[message.sender] = message.auth_counter;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auth::LabKey key = sg::fuzz::fuzz_key();
  signed_set(key);
  auth::CommandVerifier verifier(key);
  Accepted accepted;
  size_t at = 0;
  for (size_t record = 0; record < sg::fuzz::kMaxRecords && at + 3 <= size; ++record) {
    const uint8_t selector = data[at];
    const size_t length =
        std::min<size_t>((size_t{data[at + 1]} << 8) | data[at + 2], size - at - 3);
    const std::vector<uint8_t> bytes(data + at + 3, data + at + 3 + length);
    at += 3 + length;
    const int channel = (selector >> 1) & 3;
    const int64_t now = sg::fuzz::kNow + (int64_t{selector >> 3} - 16) * 4'000'000;
    if (selector & 1)
      check_one<stereograsp::grasp_command_t>(key, verifier, channel, now, bytes, accepted);
    else
      check_one<stereograsp::arm_cmd_t>(key, verifier, channel, now, bytes, accepted);
  }
  int64_t counted = 0;
  for (int v = 0; v < auth::kVerdicts; ++v)
    counted += verifier.count(static_cast<auth::Verdict>(v));
  SG_FUZZ_CHECK(counted == accepted.verified, "%lld verdicts for %lld commands",
                static_cast<long long>(counted), static_cast<long long>(accepted.verified));
  return 0;
}
