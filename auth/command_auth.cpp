#include "auth/command_auth.hpp"

#include <sodium.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace sg::auth {
namespace {

static_assert(crypto_auth_BYTES == kTagSize);
static_assert(crypto_auth_KEYBYTES == LabKey::kSize);

/// `text` quoted, as printable ASCII ('?' for anything else), at most 40 characters: a sender
/// name from the bus may be anything.
std::string quoted(const std::string& text) {
  std::string out;
  out.reserve(46);
  out.push_back('\'');
  for (std::size_t i = 0; i < text.size() && i < 40; ++i) {
    const char c = text[i];
    out.push_back(c < 0x20 || c > 0x7e ? '?' : c);
  }
  out.append(text.size() > 40 ? "...'" : "'");
  return out;
}

/// Fills `buffer` with be32(length of channel) || channel || encode(m with auth_tag zeroed).
template <class M>
void authenticated_bytes(const std::string& channel, const M& m, std::vector<uint8_t>& buffer) {
  if (channel.size() > std::numeric_limits<uint32_t>::max())
    throw std::runtime_error("channel name too long");
  M copy = m;
  std::memset(copy.auth_tag, 0, sizeof copy.auth_tag);
  const int size = copy.getEncodedSize();
  const std::size_t head = 4 + channel.size();
  buffer.resize(head + static_cast<std::size_t>(size));
  const auto length = static_cast<uint32_t>(channel.size());
  for (int i = 0; i < 4; ++i) buffer[i] = static_cast<uint8_t>(length >> (24 - 8 * i));
  std::memcpy(buffer.data() + 4, channel.data(), channel.size());
  if (copy.encode(buffer.data() + head, 0, size) != size)
    throw std::runtime_error("cannot encode the command to sign or check it");
}

template <class M>
std::array<uint8_t, kTagSize> tag_of(const LabKey& key, const std::string& channel, const M& m) {
  std::vector<uint8_t> buffer;
  authenticated_bytes(channel, m, buffer);
  std::array<uint8_t, kTagSize> tag{};
  crypto_auth(tag.data(), buffer.data(), buffer.size(), key.bytes().data());
  return tag;
}

/// Microseconds as seconds with a tenth ("%.1f", or "%.3g" beyond a million seconds).
std::string seconds(double us) {
  char text[32];
  std::snprintf(text, sizeof text, std::abs(us) < 1e12 ? "%.1f" : "%.3g", us * 1e-6);
  return text;
}

int64_t to_us(double s) { return static_cast<int64_t>(std::clamp(s, 0.0, 1e12) * 1e6); }

/// a + b, clamped to int64's range.
int64_t saturated_add(int64_t a, int64_t b) {
  int64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum))
    return b > 0 ? std::numeric_limits<int64_t>::max() : std::numeric_limits<int64_t>::min();
  return sum;
}

}  // namespace

const char* to_string(Verdict verdict) {
  switch (verdict) {
    case Verdict::kAccepted:
      return "accepted";
    case Verdict::kUnsigned:
      return "unsigned";
    case Verdict::kBadTag:
      return "bad tag";
    case Verdict::kReplayed:
      return "replayed";
    case Verdict::kStale:
      return "stale";
  }
  return "unknown";
}

CommandSigner::CommandSigner(const LabKey& key, std::string sender, Clock& clock)
    : key_(key), sender_(std::move(sender)), clock_(clock) {
  ensure_sodium();
}

template <class M>
void CommandSigner::sign_message(const std::string& channel, M& m) {
  m.sender = sender_;
  last_ = std::max(last_ + 1, clock_.utime());
  m.auth_counter = last_;
  authenticated_bytes(channel, m, buffer_);
  crypto_auth(m.auth_tag, buffer_.data(), buffer_.size(), key_.bytes().data());
}

void CommandSigner::sign(const std::string& channel, stereograsp::arm_cmd_t& command) {
  sign_message(channel, command);
}
void CommandSigner::sign(const std::string& channel, stereograsp::grasp_command_t& command) {
  sign_message(channel, command);
}

CommandVerifier::CommandVerifier(const LabKey& key, VerifierSettings settings)
    : key_(key), settings_(settings) {
  ensure_sodium();
  settings_.max_senders = std::max<std::size_t>(settings_.max_senders, 1);
}

Verification CommandVerifier::judge(Verdict verdict, std::string reason) {
  ++counts_[static_cast<int>(verdict)];
  return {verdict, std::move(reason)};
}

template <class M>
Verification CommandVerifier::verify_message(const std::string& channel, const M& m,
                                             int64_t now_utime) {
  const std::string who = quoted(m.sender);
  if (sodium_is_zero(m.auth_tag, kTagSize))
    return judge(Verdict::kUnsigned, "unsigned command from " + who + " (no auth_tag)");
  authenticated_bytes(channel, m, buffer_);
  if (crypto_auth_verify(m.auth_tag, buffer_.data(), buffer_.size(), key_.bytes().data()) != 0) {
    return judge(Verdict::kBadTag, "bad auth_tag on a command from " + who +
                                       " (another key, another channel, or changed in transit)");
  }
  Verification v = check_counter(m.sender, m.auth_counter, now_utime);
  if (v.accepted()) remember(m.sender, m.auth_counter);
  return judge(v.verdict, std::move(v.reason));
}

Verification CommandVerifier::check_counter(const std::string& sender, int64_t counter,
                                            int64_t now) {
  const std::string who = quoted(sender);
  const auto it = senders_.find(sender);
  if (it != senders_.end() && counter <= it->second.counter) {
    return {Verdict::kReplayed, "replayed: auth_counter " + std::to_string(counter) + " from " +
                                    who + " not newer than its last accepted " +
                                    std::to_string(it->second.counter)};
  }
  const int64_t oldest = saturated_add(now, -to_us(settings_.max_age));
  const int64_t newest = saturated_add(now, to_us(settings_.max_ahead));
  const double off = static_cast<double>(counter) - static_cast<double>(now);  // µs, for the text
  if (counter < oldest) {
    return {Verdict::kStale, "stale: auth_counter from " + who + " is " + seconds(-off) +
                                 " s older than this host's clock (max age " +
                                 seconds(settings_.max_age * 1e6) +
                                 " s): a command replayed from before, or clock skew between hosts"};
  }
  if (counter > newest) {
    return {Verdict::kStale, "stale: auth_counter from " + who + " is " + seconds(off) +
                                 " s ahead of this host's clock (max " +
                                 seconds(settings_.max_ahead * 1e6) +
                                 " s): clock skew between hosts"};
  }
  return {Verdict::kAccepted, ""};
}

void CommandVerifier::remember(const std::string& sender, int64_t counter) {
  ++accepted_;
  if (const auto it = senders_.find(sender); it != senders_.end()) {
    it->second = {counter, accepted_};
    return;
  }
  if (senders_.size() >= settings_.max_senders) {  // forget the longest without an accepted one
    senders_.erase(std::min_element(senders_.begin(), senders_.end(), [](auto& a, auto& b) {
      return a.second.order < b.second.order;
    }));
  }
  senders_.emplace(sender, Sender{counter, accepted_});
}

Verification CommandVerifier::verify(const std::string& channel,
                                     const stereograsp::arm_cmd_t& command, int64_t now_utime) {
  return verify_message(channel, command, now_utime);
}
Verification CommandVerifier::verify(const std::string& channel,
                                     const stereograsp::grasp_command_t& command,
                                     int64_t now_utime) {
  return verify_message(channel, command, now_utime);
}

std::array<uint8_t, kTagSize> command_tag(const LabKey& key, const std::string& channel,
                                          const stereograsp::arm_cmd_t& command) {
  ensure_sodium();
  return tag_of(key, channel, command);
}
std::array<uint8_t, kTagSize> command_tag(const LabKey& key, const std::string& channel,
                                          const stereograsp::grasp_command_t& command) {
  ensure_sodium();
  return tag_of(key, channel, command);
}

}  // namespace sg::auth
