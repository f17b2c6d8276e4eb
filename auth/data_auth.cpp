#include "auth/data_auth.hpp"

#include <sodium.h>

#include <algorithm>
#include <stdexcept>

namespace sg::auth {
namespace {

constexpr char kKeyDomain[] = "sg-otk-v1";
constexpr char kPairDomain[] = "sg-pair-v1";

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

/// The peer called `name` in `peers`, added with `key` when absent.
Peer& peer_named(std::vector<Peer>& peers, const std::string& name, const PairKey& key) {
  for (Peer& p : peers)
    if (p.name == name) return p;
  peers.push_back(Peer{name, key, {}});
  return peers.back();
}

void hash_name(crypto_generichash_state& state, const std::string& name) {
  const auto size = static_cast<unsigned char>(std::min<std::size_t>(name.size(), 255));
  crypto_generichash_update(&state, &size, 1);
  crypto_generichash_update(&state, reinterpret_cast<const unsigned char*>(name.data()), size);
}

void hash_be(crypto_generichash_state& state, uint64_t v, std::size_t bytes) {
  unsigned char b[8];
  for (std::size_t i = 0; i < bytes; ++i)
    b[i] = static_cast<unsigned char>(v >> (8 * (bytes - 1 - i)));
  crypto_generichash_update(&state, b, bytes);
}

/// The key of the (sender, instance, channel) stream in the replay table.
std::string stream_key(const std::string& channel, const VouchTrailer& t) {
  return t.sender + '\n' + std::to_string(t.instance) + '\n' + channel;
}

uint32_t random_instance() {
  ensure_sodium();
  uint32_t v = 0;
  while (v == 0) v = randombytes_random();
  return v;
}

}  // namespace

const std::vector<std::string>& known_identities() {
  static const std::vector<std::string> names = {
      "sg-camera-sim", "sg-c550-sim", "sg-vision",    "sg-predictor", "sg-grasp", "sg-grasp-ctl",
      "sg-arm-driver", "sg-arm-ctl",  "sg-calibrate", "sg-viewer",    "sg-lab",   "sg-bus-check"};
  return names;
}

const ChannelRights& default_channel_rights() {
  static const ChannelRights rights = [] {
    const std::vector<std::string> cameras = {"sg-camera-sim", "sg-vision"};
    ChannelRights r = {
        {"CAMERA_LEFT", cameras, {"sg-vision", "sg-viewer"}},
        {"CAMERA_RIGHT", cameras, {"sg-vision", "sg-viewer"}},
        {"GROUND_TRUTH", {"sg-camera-sim"}, {"sg-c550-sim"}},
        {"SIM_ARM_STATE", {"sg-c550-sim"}, {"sg-camera-sim"}},
        {"BLOB_LEFT", {"sg-vision"}, {"sg-calibrate", "sg-viewer"}},
        {"BLOB_RIGHT", {"sg-vision"}, {"sg-calibrate", "sg-viewer"}},
        {"OBJECT_POSITION", {"sg-vision"}, {"sg-predictor", "sg-grasp", "sg-viewer"}},
        {"OBJECT_TRAJECTORY", {"sg-predictor"}, {"sg-grasp", "sg-viewer"}},
        {"ARM_COMMAND", {"sg-grasp", "sg-arm-ctl", "sg-calibrate"}, {"sg-arm-driver"}},
        {"ARM_STATUS", {"sg-arm-driver"}, {"sg-grasp", "sg-arm-ctl", "sg-calibrate"}},
        {"GRASP_COMMAND", {"sg-grasp-ctl"}, {"sg-grasp"}},
        {"GRASP_STATUS", {"sg-grasp"}, {"sg-grasp-ctl", "sg-viewer"}},
        {"PROCESS_STATUS", known_identities(), known_identities()},
    };
    return r;
  }();
  return rights;
}

PairKey::~PairKey() { sodium_memzero(bytes_.data(), bytes_.size()); }

PairKey pair_key(const LabKey& lab, const std::string& sender, const std::string& reader) {
  ensure_sodium();
  crypto_generichash_state state;
  crypto_generichash_init(&state, lab.bytes().data(), lab.bytes().size(), PairKey::kSize);
  crypto_generichash_update(&state, reinterpret_cast<const unsigned char*>(kPairDomain),
                            sizeof kPairDomain - 1);
  hash_name(state, sender);
  hash_name(state, reader);
  std::array<uint8_t, PairKey::kSize> bytes{};
  crypto_generichash_final(&state, bytes.data(), bytes.size());
  PairKey key(bytes);
  sodium_memzero(bytes.data(), bytes.size());
  return key;
}

bool is_command_channel(const std::string& channel) {
  return channel == "ARM_COMMAND" || channel == "GRASP_COMMAND";
}

Credentials credentials_from_lab_key(const LabKey& lab, const std::string& identity,
                                     const ChannelRights& rights) {
  if (!valid_vouch_name(identity))
    throw std::invalid_argument("'" + identity +
                                "' cannot vouch: a name is 1-32 letters, "
                                "digits or . _ @ : -");
  Credentials c;
  c.identity = identity;
  for (const ChannelRight& right : rights) {
    if (contains(right.publishers, identity)) {
      for (const std::string& reader : right.readers)
        peer_named(c.send, reader, pair_key(lab, identity, reader))
            .channels.push_back(right.channel);
    }
    if (contains(right.readers, identity)) {
      for (const std::string& publisher : right.publishers)
        peer_named(c.receive, publisher, pair_key(lab, publisher, identity))
            .channels.push_back(right.channel);
    }
    const bool party = contains(right.publishers, identity) || contains(right.readers, identity);
    if (party && is_command_channel(right.channel) && !c.command_key)
      c.command_key = command_key(lab);
  }
  return c;
}

std::array<uint8_t, 32> one_time_key(const PairKey& key, const std::string& channel,
                                     const VouchTrailer& trailer) {
  crypto_generichash_state state;
  crypto_generichash_init(&state, key.bytes().data(), key.bytes().size(), 32);
  crypto_generichash_update(&state, reinterpret_cast<const unsigned char*>(kKeyDomain),
                            sizeof kKeyDomain - 1);
  hash_name(state, channel);
  hash_name(state, trailer.sender);
  hash_be(state, trailer.instance, 4);
  hash_be(state, static_cast<uint64_t>(trailer.counter), 8);
  std::array<uint8_t, 32> k{};
  crypto_generichash_final(&state, k.data(), k.size());
  return k;
}

std::array<uint8_t, kVouchTagSize> vouch_tag(const PairKey& key, const std::string& channel,
                                             const VouchTrailer& trailer, const uint8_t* payload,
                                             std::size_t size) {
  static_assert(kVouchTagSize == crypto_onetimeauth_BYTES);
  std::array<uint8_t, 32> k = one_time_key(key, channel, trailer);
  std::array<uint8_t, kVouchTagSize> tag{};
  crypto_onetimeauth(tag.data(), payload, size, k.data());
  sodium_memzero(k.data(), k.size());
  return tag;
}

DataGuard::DataGuard(Credentials credentials, DataGuardSettings settings, Clock& clock,
                     uint32_t instance)
    : credentials_(std::move(credentials)),
      settings_(settings),
      clock_(clock),
      instance_(instance != 0 ? instance : random_instance()) {
  ensure_sodium();
  if (!valid_vouch_name(credentials_.identity))
    throw std::invalid_argument("'" + credentials_.identity + "' cannot vouch: not a name");
  for (const Peer& p : credentials_.send)
    if (!valid_vouch_name(p.name))
      throw std::invalid_argument("credentials: '" + p.name + "' is not a reader's name");
}

const std::vector<std::size_t>& DataGuard::readers_of(const std::string& channel) {
  auto found = readers_.find(channel);
  if (found != readers_.end()) return found->second;
  std::vector<std::size_t> readers;
  for (std::size_t i = 0; i < credentials_.send.size() && readers.size() < kVouchMaxTags; ++i)
    if (contains(credentials_.send[i].channels, channel)) readers.push_back(i);
  if (readers_.size() >= 1024) readers_.clear();  // channels named by a caller: stay bounded
  return readers_.emplace(channel, std::move(readers)).first->second;
}

void DataGuard::vouch(const std::string& channel, std::vector<uint8_t>& message) {
  VouchTrailer t;
  t.sender = credentials_.identity;
  t.instance = instance_;
  last_counter_ = std::max(last_counter_ + 1, clock_.utime());
  t.counter = last_counter_;
  const std::vector<std::size_t>& readers = readers_of(channel);
  t.tags.reserve(readers.size());
  for (const std::size_t i : readers) {
    const Peer& reader = credentials_.send[i];
    t.tags.push_back(
        VouchTag{reader.name, vouch_tag(reader.key, channel, t, message.data(), message.size())});
  }
  append_vouch_trailer(message, t);
}

GuardResult DataGuard::judge(GuardVerdict verdict, std::string sender, std::string reason) {
  ++counts_[static_cast<int>(verdict)];
  GuardResult r;
  r.verdict = verdict;
  r.sender = std::move(sender);
  r.reason = std::move(reason);
  return r;
}

GuardResult DataGuard::check(const std::string& channel, const uint8_t* data, std::size_t size,
                             int64_t now_utime) {
  const TrailerParse p = parse_vouch_trailer(data, size);
  if (p.kind == TrailerParse::kNone)
    return judge(GuardVerdict::kUnsigned, "", "no vouching trailer");
  if (p.kind == TrailerParse::kMalformed) return judge(GuardVerdict::kMalformed, "", p.why);
  const VouchTrailer& t = p.trailer;
  const Peer* sender = nullptr;
  for (const Peer& peer : credentials_.receive)
    if (peer.name == t.sender && contains(peer.channels, channel)) sender = &peer;
  if (sender == nullptr)
    return judge(GuardVerdict::kNotAllowed, t.sender,
                 "'" + t.sender + "' may not publish here (to " + credentials_.identity + ")");
  const auto mine = std::find_if(t.tags.begin(), t.tags.end(), [&](const VouchTag& tag) {
    return tag.reader == credentials_.identity;
  });
  if (mine == t.tags.end())
    return judge(GuardVerdict::kNoTag, t.sender,
                 "'" + t.sender + "' vouched for " + std::to_string(t.tags.size()) +
                     " readers, not for " + credentials_.identity);
  std::array<uint8_t, 32> k = one_time_key(sender->key, channel, t);
  const bool good =
      crypto_onetimeauth_verify(mine->tag.data(), data, p.payload_size, k.data()) == 0;
  sodium_memzero(k.data(), k.size());
  if (!good) return judge(GuardVerdict::kBadTag, t.sender, "bad tag from '" + t.sender + "'");
  GuardResult r = check_counter(channel, t, now_utime);
  if (r.accepted()) r.payload_size = p.payload_size;
  return r;
}

GuardResult DataGuard::check_counter(const std::string& channel, const VouchTrailer& t,
                                     int64_t now_utime) {
  const std::string key = stream_key(channel, t);
  const auto known = streams_.find(key);
  if (known != streams_.end() && t.counter <= known->second.counter)
    return judge(GuardVerdict::kReplayed, t.sender,
                 "replayed: counter " + std::to_string(t.counter) + " of '" + t.sender +
                     "' not newer than " + std::to_string(known->second.counter));
  const auto us = [](double s) { return static_cast<int64_t>(s * 1e6); };
  if (t.counter < now_utime - us(settings_.max_age) ||
      t.counter > now_utime + us(settings_.max_ahead)) {
    const double off = (static_cast<double>(t.counter) - static_cast<double>(now_utime)) * 1e-6;
    return judge(GuardVerdict::kStale, t.sender,
                 "stale: '" + t.sender + "' vouched at " + std::to_string(off) +
                     " s from this clock (a recorded message, or a clock off by that much)");
  }
  remember(key, t.counter);
  return judge(GuardVerdict::kAccepted, t.sender, "");
}

void DataGuard::remember(const std::string& stream, int64_t counter) {
  auto found = streams_.find(stream);
  if (found == streams_.end()) {
    if (streams_.size() >= settings_.max_streams) {
      auto oldest = std::min_element(streams_.begin(), streams_.end(), [](auto& a, auto& b) {
        return a.second.order < b.second.order;
      });
      streams_.erase(oldest);
    }
    found = streams_.emplace(stream, Stream{}).first;
  }
  found->second.counter = counter;
  found->second.order = ++accepted_;
}

}  // namespace sg::auth
