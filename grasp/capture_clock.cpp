#include "grasp/capture_clock.hpp"

#include <cstdio>

namespace sg::grasp {
namespace {

/// The newest-heard process that has published on `channel`, or nullptr.
const ProcessWatch::Process* publisher(const ProcessWatch& watch, const std::string& channel) {
  const ProcessWatch::Process* found = nullptr;
  for (const ProcessWatch::Process& p : watch.processes()) {
    const auto& s = p.last;
    const size_t n = std::min(s.channel.size(), s.messages_out.size());
    for (size_t i = 0; i < n; ++i)
      if (s.channel[i] == channel && s.messages_out[i] > 0 &&
          (!found || p.last_heard > found->last_heard))
        found = &p;
  }
  return found;
}

}  // namespace

CaptureClock::Estimate CaptureClock::estimate(const ProcessWatch& watch, const ClockSync& sync,
                                              const std::string& self_host) {
  Estimate e;
  std::string channel = "CAMERA_LEFT";
  const ProcessWatch::Process* p = publisher(watch, channel);
  if (!p) p = publisher(watch, channel = "OBJECT_POSITION");
  if (!p) return e;  // nothing heard yet: the times are taken as they are
  e.host = p->last.host;
  e.source = p->name + " (" + channel + ")";
  if (e.host == self_host) {
    e.usable = true;
    e.error_us = 0;
    return e;
  }
  for (const ClockSync::Offset& o : sync.offsets())
    if (o.host == e.host && o.known && (e.error_us < 0 || o.error_us < e.error_us))
      e.offset_us = o.offset_us, e.error_us = o.error_us;
  if (e.error_us < 0) {
    e.why = "capture clock on " + e.host + " (" + e.source + "): no clock exchange with it yet";
  } else if (e.error_us > kMaxError) {
    char text[200];
    std::snprintf(text, sizeof text, "capture clock on %s: offset %+.1f ms known only to ± %.1f ms",
                  e.host.c_str(), e.offset_us / 1e3, e.error_us / 1e3);
    e.why = text;
  } else {
    e.usable = true;
  }
  return e;
}

}  // namespace sg::grasp
