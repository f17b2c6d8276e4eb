#pragma once

/// Clock offsets between the processes of a lab, measured from their heartbeats (issue 18).
///
/// Every announced process publishes process_status_t on PROCESS_STATUS once a second, and in it
/// echoes the newest status it heard from each other process: when it was sent (the sender's
/// clock) and when it arrived (its own clock). Those echoes are NTP's on-wire exchange (RFC 5905,
/// section 8) carried by the heartbeats: process A sends a status at t1 (A's clock); B receives
/// it at t2 (B's clock) and echoes (t1, t2) in its next status, sent at t3 (B's clock); A
/// receives that at t4 (A's clock). Then
///
///     offset  θ = ((t2 − t1) + (t3 − t4)) / 2      (B's clock minus A's)
///     delay   δ = (t4 − t1) − (t3 − t2)            (the round trip, B's hold time taken out)
///
/// and B's true offset lies within θ ± δ/2 however unequal the two paths are (B holds the echo
/// up to a second, over which two quartz clocks 50 ppm apart drift 50 µs: a term the bound
/// leaves out). Of the last 8 exchanges with a peer the one of least δ is
/// kept, as NTP's clock filter does: a datagram delayed by a loaded host only widens its own δ.
///
///     sg::ClockSync sync("sg-grasp@lab2:812");
///     sync.receive(peer_status, info.recv_utime);  // every PROCESS_STATUS heard
///     sync.fill(my_status);                        // before publishing mine (sets its echoes)
///     if (auto o = sync.offset("sg-vision@lab1:77"); o && o->known)
///       std::printf("lab1 is %+.1f ms ± %.1f ms\n", o->offset_us / 1e3, o->error_us / 1e3);
///
/// Nothing here is authenticated (neither is LCM): a hostile host can make up echoes and so
/// offsets. Offsets are a diagnosis shown to people; an exchange whose t1 is not one of our own
/// recent statuses, or whose delay is negative or over 10 s, is ignored, and no value a status
/// carries can overflow the arithmetic or grow the peer table past kMaxPeers.

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "stereograsp/process_status_t.hpp"

namespace sg {

/// "process@host:pid": how a status names its sender, and how echoes name their peers.
std::string status_sender(const stereograsp::process_status_t& status);

/// The NTP-style clock offsets of this process to every other one that publishes a status.
class ClockSync {
 public:
  /// Peers remembered (and echoed); beyond that the longest silent is forgotten.
  static constexpr size_t kMaxPeers = 64;
  /// Exchanges kept per peer (NTP's clock filter holds 8).
  static constexpr size_t kFilterLength = 8;
  /// Our own statuses remembered, so an echo of one can be recognised.
  static constexpr size_t kOwnStatuses = 16;
  /// A peer silent this long is no longer echoed (its echo would only add a stale exchange).
  static constexpr int64_t kEchoFor = 10'000'000;
  /// Longest peer name kept: longer ones are not real processes' names.
  static constexpr size_t kMaxName = 200;

  /// `self`: this process as status_sender() names it.
  explicit ClockSync(std::string self);

  /// A peer's clock relative to ours.
  struct Offset {
    std::string peer;        ///< "process@host:pid"
    std::string host;        ///< the peer's host (status.host)
    bool known = false;      ///< an exchange completed
    int64_t offset_us = 0;   ///< θ: its clock minus ours
    int64_t error_us = -1;   ///< δ/2 of the exchange θ comes from; -1 while not known
    int64_t last_heard = 0;  ///< our clock when its newest status arrived
    int64_t exchanges = 0;   ///< completed exchanges since first heard
  };

  /// Takes a status received at `recv_utime` (our clock): remembers it to echo, and completes an
  /// exchange if it echoes one of ours. Our own statuses (looped back by LCM) are ignored.
  void receive(const stereograsp::process_status_t& status, int64_t recv_utime);

  /// Fills `status`'s echoes and offsets (peer, peer_utime, peer_recv_utime, peer_offset_us,
  /// peer_offset_error_us, num_peers) and remembers status.utime as sent.
  void fill(stereograsp::process_status_t& status);

  /// Every peer heard, in the order first heard.
  std::vector<Offset> offsets() const;
  /// One peer, by name.
  std::optional<Offset> offset(const std::string& peer) const;

  /// Echoes refused: a t1 not ours, a delay out of range, a name too long.
  uint64_t ignored() const { return ignored_; }

 private:
  struct Exchange {
    int64_t offset_us, delay_us;
  };
  struct Peer {
    Offset offset;
    int64_t last_utime = 0;  // t3 of its newest status (its clock), to echo
    std::deque<Exchange> filter;
  };
  Peer* find(const std::string& name);
  Peer& admit(const stereograsp::process_status_t& status, const std::string& name);
  void complete_exchange(Peer& peer, int64_t t1, int64_t t2, int64_t t3, int64_t t4);

  std::string self_;
  std::deque<Peer> peers_;
  std::deque<int64_t> sent_;  // utimes of our recent statuses
  uint64_t ignored_ = 0;
};

}  // namespace sg
