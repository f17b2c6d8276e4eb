#include "common/process_watch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "common/clock_sync.hpp"

namespace sg {
namespace {

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", s);
  return text;
}

std::string milliseconds(int64_t us) {
  char text[48];
  std::snprintf(text, sizeof text, "%+.1f ms", static_cast<double>(us) / 1e3);
  return text;
}

/// "3 s", "4 min", "2.5 h": an uptime.
std::string duration(double s) {
  char text[32];
  if (s < 120) {
    std::snprintf(text, sizeof text, "%.0f s", s);
  } else if (s < 7200) {
    std::snprintf(text, sizeof text, "%.0f min", s / 60);
  } else {
    std::snprintf(text, sizeof text, "%.1f h", s / 3600);
  }
  return text;
}

double sum(const std::vector<double>& values) {
  double total = 0;
  for (double v : values)
    if (std::isfinite(v)) total += v;
  return total;
}

}  // namespace

std::string state_name(int8_t state) {
  using S = stereograsp::process_status_t;
  switch (state) {
    case S::STATE_STARTING:
      return "starting";
    case S::STATE_READY:
      return "ready";
    case S::STATE_STOPPING:
      return "stopping";
    default:
      return "state " + std::to_string(state);
  }
}

ProcessWatch::Process& ProcessWatch::admit(const std::string& name, int64_t recv_utime) {
  for (Process& p : processes_)
    if (p.name == name) return p;
  if (processes_.size() >= kMaxProcesses) {
    const auto oldest =
        std::min_element(processes_.begin(), processes_.end(),
                         [](auto& a, auto& b) { return a.last_heard < b.last_heard; });
    processes_.erase(oldest);
  }
  Process& p = processes_.emplace_back();
  p.name = name;
  p.first_heard = recv_utime;
  pending_.push_back({Event::kJoined, name, recv_utime, name + " joined"});
  return p;
}

void ProcessWatch::receive(const stereograsp::process_status_t& status, int64_t recv_utime) {
  const std::string name = status_sender(status);
  if (name.size() > ClockSync::kMaxName) return;
  Process& p = admit(name, recv_utime);
  if (p.silent) {
    p.silent = false;
    pending_.push_back({Event::kBack, name, recv_utime,
                        name + " beats again after " + seconds((recv_utime - p.last_heard) / 1e6) +
                            " of silence"});
  }
  const bool was_stopping = p.last.state == stereograsp::process_status_t::STATE_STOPPING;
  p.last = status;
  p.last_heard = recv_utime;
  if (status.state == stereograsp::process_status_t::STATE_STOPPING && !was_stopping)
    pending_.push_back({Event::kStopped, name, recv_utime, name + " stopped"});
}

std::vector<ProcessWatch::Event> ProcessWatch::check(int64_t now) {
  std::vector<Event> events = std::move(pending_);
  pending_.clear();
  for (Process& p : processes_) {
    if (p.silent || p.last.state == stereograsp::process_status_t::STATE_STOPPING) continue;
    const double silence = (now - p.last_heard) / 1e6;
    if (silence < kSilentAfter) continue;
    p.silent = true;
    events.push_back({Event::kStoppedBeating, p.name, now,
                      p.name + " stopped beating (silent " + seconds(silence) + ")"});
  }
  return events;
}

const ProcessWatch::Process* ProcessWatch::find(const std::string& name_or_program) const {
  const Process* found = nullptr;
  for (const Process& p : processes_) {
    if (p.name == name_or_program) return &p;
    if (p.last.process == name_or_program && (!found || p.last_heard > found->last_heard))
      found = &p;
  }
  return found;
}

std::vector<std::string> ProcessWatch::hosts() const {
  std::vector<std::string> hosts;
  for (const Process& p : processes_)
    if (std::find(hosts.begin(), hosts.end(), p.last.host) == hosts.end())
      hosts.push_back(p.last.host);
  return hosts;
}

std::vector<ProcessWatch::HostOffset> ProcessWatch::host_offsets(
    const std::string& reference) const {
  std::vector<HostOffset> offsets;
  for (const std::string& host : hosts()) offsets.push_back({host});
  auto host_of = [&](const std::string& peer) -> std::string {
    for (const Process& p : processes_)
      if (p.name == peer) return p.last.host;
    return {};
  };
  auto consider = [&](const std::string& host, int64_t offset, int64_t error) {
    for (HostOffset& h : offsets) {
      if (h.host != host || error < 0 || (h.known && h.error_us <= error)) continue;
      h.known = true, h.offset_us = offset, h.error_us = error;
    }
  };
  for (const Process& p : processes_) {
    const auto& s = p.last;
    const size_t n = std::min({static_cast<size_t>(std::max(s.num_peers, 0)), s.peer.size(),
                               s.peer_offset_us.size(), s.peer_offset_error_us.size()});
    for (size_t i = 0; i < n; ++i) {
      const std::string peer_host = host_of(s.peer[i]);
      if (s.host == reference && !peer_host.empty())
        consider(peer_host, s.peer_offset_us[i], s.peer_offset_error_us[i]);
      else if (peer_host == reference && s.peer_offset_us[i] > INT64_MIN)
        consider(s.host, -s.peer_offset_us[i], s.peer_offset_error_us[i]);
    }
  }
  for (HostOffset& h : offsets)
    if (h.host == reference) h.known = true, h.offset_us = 0, h.error_us = 0;
  return offsets;
}

std::string format_processes(const ProcessWatch& watch, int64_t now) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-28s %-14s %-12s %8s %8s %8s %6s %9s  %s\n", "PROCESS", "HOST",
                "STATE", "UP", "IN/s", "OUT/s", "BAD", "UNVOUCHED", "LAST PROBLEM");
  out += line;
  for (const ProcessWatch::Process& p : watch.processes()) {
    const auto& s = p.last;
    const double silence = (now - p.last_heard) / 1e6;
    std::string state = state_name(s.state);
    if (s.state != stereograsp::process_status_t::STATE_STOPPING &&
        silence >= ProcessWatch::kSilentAfter)
      state = "silent " + seconds(silence);
    const double up = (s.utime - s.start_utime) / 1e6 + silence;
    const long long bad = s.decode_errors + s.refused_inputs + s.handler_errors;
    std::string problem = s.last_problem;
    if (!s.state_detail.empty()) problem = s.state_detail + (problem.empty() ? "" : "; " + problem);
    const std::string unvouched =
        s.vouched_as.empty() ? "insecure" : std::to_string(s.unvouched_inputs);
    std::snprintf(line, sizeof line, "%-28s %-14s %-12s %8s %8.1f %8.1f %6lld %9s  %s\n",
                  (s.process + ":" + std::to_string(s.pid)).c_str(), s.host.c_str(), state.c_str(),
                  s.start_utime > 0 && up >= 0 ? duration(up).c_str() : "?", sum(s.rate_in_hz),
                  sum(s.rate_out_hz), bad, unvouched.c_str(), problem.substr(0, 200).c_str());
    out += line;
  }
  return out;
}

std::string format_clocks(const std::vector<ProcessWatch::HostOffset>& offsets,
                          const std::string& reference) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-14s %s\n", "HOST", ("CLOCK - " + reference).c_str());
  out += line;
  for (const auto& h : offsets) {
    char bound[32];
    std::snprintf(bound, sizeof bound, " ± %.1f ms", h.error_us / 1e3);
    const std::string value = h.host == reference ? "0 (reference)"
                              : h.known           ? milliseconds(h.offset_us) + bound
                                                  : "unknown (no exchange yet)";
    std::snprintf(line, sizeof line, "%-14s %s\n", h.host.c_str(), value.c_str());
    out += line;
  }
  return out;
}

std::vector<std::string> clock_warnings(const std::vector<ProcessWatch::HostOffset>& offsets,
                                        const std::string& reference, int64_t tolerance_us) {
  std::vector<std::string> warnings;
  for (const auto& h : offsets) {
    if (!h.known || h.host == reference) continue;
    if (std::llabs(h.offset_us) - h.error_us <= tolerance_us) continue;
    char line[512];
    std::snprintf(line, sizeof line,
                  "clock of host %s is %s off %s's (± %.1f ms; the loop tolerates %.0f ms): "
                  "synchronise the clocks (docs/lab.md, chrony)",
                  h.host.c_str(), milliseconds(h.offset_us).c_str(), reference.c_str(),
                  h.error_us / 1e3, tolerance_us / 1e3);
    warnings.emplace_back(line);
  }
  return warnings;
}

}  // namespace sg
