#pragma once

/// Who is on the bus, from their heartbeats (issue 18): every announced process publishes
/// process_status_t on PROCESS_STATUS once a second; a watcher (sg-lab status and watch,
/// sg-bus-check health, sg-report over a log) keeps the newest status of each and when it came.
///
///     sg::ProcessWatch watch;
///     bus.subscribe<process_status_t>("PROCESS_STATUS", [&](auto& s, auto& info) {
///       watch.receive(s, info.recv_utime);
///     });
///     for (const auto& event : watch.check(sg::now_utime()))   // joined, stopped beating, ...
///       std::puts(event.line.c_str());
///
/// Silence is judged by receive times on the watcher's own clock, never by the utime a status
/// carries, so a host whose clock is wrong is still watched right. A process that stops beating
/// for kSilentAfter (2.5 s: two missed beats and a half) is reported; one whose last status said
/// STATE_STOPPING stopped cleanly. Host clock offsets come from the offsets the processes measured
/// themselves and publish (sg::ClockSync), so a log alone tells them.
///
/// At most kMaxProcesses are kept (a hostile host can invent any number of names): beyond that
/// the longest silent is forgotten.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "stereograsp/process_status_t.hpp"

namespace sg {

class ProcessWatch {
 public:
  static constexpr size_t kMaxProcesses = 256;
  /// s without a heartbeat after which a process is reported as stopped beating.
  static constexpr double kSilentAfter = 2.5;

  /// One process as last heard.
  struct Process {
    std::string name;  ///< "process@host:pid" (status_sender)
    stereograsp::process_status_t last;
    int64_t first_heard = 0;  ///< watcher's clock
    int64_t last_heard = 0;   ///< watcher's clock
    bool silent = false;      ///< reported as stopped beating, not heard since
  };

  /// What changed, as check() reports it.
  struct Event {
    enum Kind { kJoined, kStoppedBeating, kBack, kStopped } kind;
    std::string name;
    int64_t utime = 0;  ///< watcher's clock
    std::string line;   ///< one line for people: "sg-vision@lab1:77 stopped beating (silent 2.6 s)"
  };

  /// One host's clock against the reference host's, as the processes measured it.
  struct HostOffset {
    std::string host;
    bool known = false;
    int64_t offset_us = 0;  ///< its clock minus the reference host's
    int64_t error_us = -1;  ///< bound on the error of offset_us
  };

  /// Takes a status received at `recv_utime` (the watcher's clock).
  void receive(const stereograsp::process_status_t& status, int64_t recv_utime);

  /// Events since the last check at `now` (the watcher's clock): processes that joined, stopped
  /// beating, came back, or stopped cleanly.
  std::vector<Event> check(int64_t now);

  /// Every process heard, in the order first heard.
  const std::vector<Process>& processes() const { return processes_; }
  /// One process by name ("process@host:pid"), or the newest instance of a program ("sg-vision").
  const Process* find(const std::string& name_or_program) const;

  /// Every host's clock offset to `reference` (a host name), from the offsets the processes
  /// published: the estimate of least error among the pairs (reference, host) either way round.
  std::vector<HostOffset> host_offsets(const std::string& reference) const;

  /// The hosts heard, in the order first heard.
  std::vector<std::string> hosts() const;

 private:
  Process& admit(const std::string& name, int64_t recv_utime);

  std::vector<Process> processes_;
  std::vector<Event> pending_;  // joined events, reported by the next check()
};

/// A process_status_t state as a word: "starting", "ready", "stopping", "state 7".
std::string state_name(int8_t state);

/// The clock offset between hosts beyond which they are warned about (docs/lab.md): the grasp
/// machine times a close on one host by a forecast stamped on another, so an offset Δ moves the
/// close by Δ; at 0.05 m/s (the paper's ball, 0.15 m at 3 rpm) 20 ms is 1 mm of the gripper's
/// tolerance. chrony on a lab network holds well under 1 ms.
inline constexpr int64_t kClockToleranceUs = 20'000;

/// A row per process for people: name, host, state (or "silent 4.2 s"), uptime, messages in and
/// out per second, bad messages (refused, undecodable, failed), the last problem. `now`: the
/// watcher's clock.
std::string format_processes(const ProcessWatch& watch, int64_t now);

/// A row per host: its clock offset to `reference` with its error bound, or "unknown".
std::string format_clocks(const std::vector<ProcessWatch::HostOffset>& offsets,
                          const std::string& reference);

/// One line per host whose clock is surely (|offset| − error) more than `tolerance_us` off the
/// reference: "clock of host lab1 is -812.3 ms off lab2's (± 0.4 ms; the loop tolerates 20 ms):
/// synchronise the clocks (docs/lab.md)".
std::vector<std::string> clock_warnings(const std::vector<ProcessWatch::HostOffset>& offsets,
                                        const std::string& reference,
                                        int64_t tolerance_us = kClockToleranceUs);

}  // namespace sg
