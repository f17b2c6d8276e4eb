#pragma once

/// A kernel filter on a socket of an LCM `udpm://` bus: only the datagrams of the channels a
/// process subscribes to wake it (issue 19). Every LCM process on a multicast group receives every
/// datagram sent to it and drops what it has no subscription for only after reading it: on a
/// 2-vCPU machine each camera frame woke three receive threads that then threw it away, and
/// sg-vision's p99 latency paid for it (docs/performance.md).
///
///     sg::attach_lcm_channel_filter(fd, {"OBJECT_POSITION", "PROCESS_STATUS"});
///     // the kernel now drops, before any thread wakes, the messages of other channels
///
/// The filter is a classic BPF program (SO_ATTACH_FILTER, `man 7 socket`) over LCM's datagram
/// format (lcm_udpm.c, LCM 1.3.1; sg::LcmDatagramAssembler reads the same):
///
///     short message  "LC02" (4) | sequence (4) | channel, NUL-terminated | payload
///     fragment       "LC03" (4) | sequence (4) | message size (4) | offset (4)
///                    | fragment number (2) | fragments (2) | [fragment 0 only: channel, NUL] | ...
///
/// It drops a short message, or a message's first fragment, that is well formed (its channel a
/// name of 1 to 63 bytes ended by its NUL, LCM's limit) and on a channel that is none of
/// `channels`: what a subscriber to `channels` skips without a word. Everything else passes:
/// the wanted channels; every later fragment (those carry no channel; the reader drops them when
/// it holds no first fragment of theirs); and every datagram that is not LCM's or breaks its
/// format, for the reader to refuse and count with its reason. What the filter drops the kernel
/// counts as the socket's drops (/proc/net/udp, SO_MEMINFO).

#include <linux/filter.h>

#include <cstdint>
#include <string>
#include <vector>

namespace sg {

/// The program for `channels` (each a channel name of at most 63 bytes, LCM's limit; throws
/// std::invalid_argument otherwise). Offsets count from the UDP header, where a UDP socket's
/// filter starts.
std::vector<sock_filter> lcm_channel_filter(const std::vector<std::string>& channels);

/// Attaches lcm_channel_filter(channels) to socket `fd`, replacing any filter it had; throws
/// std::runtime_error (one line, with the reason) when the kernel refuses.
void attach_lcm_channel_filter(int fd, const std::vector<std::string>& channels);

/// Removes the filter from `fd` (every datagram is delivered again); true when one was attached.
bool detach_lcm_channel_filter(int fd);

/// This process's UDP sockets bound to `port` (of any address), by descriptor: LCM keeps its
/// receive socket to itself, so the bus finds it as the one that appeared when LCM set up
/// receiving (sg::Bus).
std::vector<int> udp_sockets_bound_to(uint16_t port);

/// True when LCM subscription `regex` (which LCM anchors, "^regex$") matches exactly one channel,
/// itself: a name of letters, digits, '_', '-', '/', ':' of at most 63 bytes, no metacharacter.
bool is_plain_channel_name(const std::string& regex);

}  // namespace sg
