#include "common/clock_sync.hpp"

#include <algorithm>
#include <utility>

namespace sg {
namespace {

/// a - b, or nullopt when it does not fit in an int64 (times from a hostile status).
std::optional<int64_t> difference(int64_t a, int64_t b) {
  int64_t d = 0;
  if (__builtin_sub_overflow(a, b, &d)) return std::nullopt;
  return d;
}

/// Longest round trip an exchange may have: beyond it the echo is not of a live exchange.
constexpr int64_t kMaxDelay = 10'000'000;

}  // namespace

std::string status_sender(const stereograsp::process_status_t& status) {
  return status.process + "@" + status.host + ":" + std::to_string(status.pid);
}

ClockSync::ClockSync(std::string self) : self_(std::move(self)) {}

ClockSync::Peer* ClockSync::find(const std::string& name) {
  for (Peer& p : peers_)
    if (p.offset.peer == name) return &p;
  return nullptr;
}

ClockSync::Peer& ClockSync::admit(const stereograsp::process_status_t& status,
                                  const std::string& name) {
  if (Peer* p = find(name)) return *p;
  if (peers_.size() >= kMaxPeers) {
    const auto silent = std::min_element(peers_.begin(), peers_.end(), [](auto& a, auto& b) {
      return a.offset.last_heard < b.offset.last_heard;
    });
    peers_.erase(silent);
  }
  Peer& p = peers_.emplace_back();
  p.offset.peer = name;
  p.offset.host = status.host;
  return p;
}

void ClockSync::receive(const stereograsp::process_status_t& status, int64_t recv_utime) {
  const std::string name = status_sender(status);
  if (name == self_) return;
  if (name.size() > kMaxName) {
    ++ignored_;
    return;
  }
  Peer& peer = admit(status, name);
  peer.offset.last_heard = recv_utime;
  peer.last_utime = status.utime;
  // Our echo in its status, if any: the newest of ours it heard.
  const size_t n = std::min({static_cast<size_t>(std::max(status.num_peers, 0)), status.peer.size(),
                             status.peer_utime.size(), status.peer_recv_utime.size()});
  for (size_t i = 0; i < n; ++i) {
    if (status.peer[i] != self_) continue;
    complete_exchange(peer, status.peer_utime[i], status.peer_recv_utime[i], status.utime,
                      recv_utime);
    break;
  }
}

void ClockSync::complete_exchange(Peer& peer, int64_t t1, int64_t t2, int64_t t3, int64_t t4) {
  if (std::find(sent_.begin(), sent_.end(), t1) == sent_.end()) {
    ++ignored_;  // not one of our recent statuses: an old echo, or a made-up one
    return;
  }
  const auto out = difference(t2, t1), back = difference(t3, t4);
  const auto trip = difference(t4, t1), hold = difference(t3, t2);
  if (!out || !back || !trip || !hold) {
    ++ignored_;
    return;
  }
  const auto delay = difference(*trip, *hold);
  if (!delay || *delay < 0 || *delay > kMaxDelay) {
    ++ignored_;
    return;
  }
  int64_t sum = 0;
  if (__builtin_add_overflow(*out, *back, &sum)) {
    ++ignored_;
    return;
  }
  const int64_t offset = sum / 2;
  peer.filter.push_back({offset, *delay});
  if (peer.filter.size() > kFilterLength) peer.filter.pop_front();
  const Exchange& best =
      *std::min_element(peer.filter.begin(), peer.filter.end(),
                        [](auto& a, auto& b) { return a.delay_us < b.delay_us; });
  peer.offset.known = true;
  peer.offset.offset_us = best.offset_us;
  peer.offset.error_us = (best.delay_us + 1) / 2;
  ++peer.offset.exchanges;
}

void ClockSync::fill(stereograsp::process_status_t& status) {
  sent_.push_back(status.utime);
  if (sent_.size() > kOwnStatuses) sent_.pop_front();
  status.peer.clear();
  status.peer_utime.clear();
  status.peer_recv_utime.clear();
  status.peer_offset_us.clear();
  status.peer_offset_error_us.clear();
  for (const Peer& p : peers_) {
    const auto since = difference(status.utime, p.offset.last_heard);
    if (!since || *since > kEchoFor) continue;
    status.peer.push_back(p.offset.peer);
    status.peer_utime.push_back(p.last_utime);
    status.peer_recv_utime.push_back(p.offset.last_heard);
    status.peer_offset_us.push_back(p.offset.known ? p.offset.offset_us : 0);
    status.peer_offset_error_us.push_back(p.offset.known ? p.offset.error_us : -1);
  }
  status.num_peers = static_cast<int32_t>(status.peer.size());
}

std::vector<ClockSync::Offset> ClockSync::offsets() const {
  std::vector<Offset> all;
  for (const Peer& p : peers_) all.push_back(p.offset);
  return all;
}

std::optional<ClockSync::Offset> ClockSync::offset(const std::string& peer) const {
  for (const Peer& p : peers_)
    if (p.offset.peer == peer) return p.offset;
  return std::nullopt;
}

}  // namespace sg
