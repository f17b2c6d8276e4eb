#pragma once

/// Keeps a hostile or broken publisher from flooding the log (issue 15): of each kind of line, the
/// first `burst` are logged, then at most one every `period` seconds, which tells how many of its
/// kind were held back since the last one logged. Pure: the caller gives the time.
///
///     LogLimiter limit;                                   // 10, then one a second
///     if (uint64_t held_back = 0; limit.allow("rejected", clock.now(), held_back))
///       spdlog::warn("rejected ... ({} more not logged)", held_back);

#include <cstdint>
#include <map>
#include <string>

namespace sg::arm {

class LogLimiter {
 public:
  explicit LogLimiter(int burst = 10, double period = 1.0) : burst_(burst), period_(period) {}

  /// Whether a line of `kind` at `t` (seconds) is logged; when it is, `suppressed` is set to how
  /// many of its kind were not logged since the last one that was.
  bool allow(const std::string& kind, double t, uint64_t& suppressed);

 private:
  struct Kind {
    uint64_t seen = 0;
    uint64_t suppressed = 0;
    double last_logged = 0;
  };
  int burst_;
  double period_;
  std::map<std::string, Kind> kinds_;
};

}  // namespace sg::arm
