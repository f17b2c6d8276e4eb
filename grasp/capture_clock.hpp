#pragma once

/// Whose clock the forecast's times are on, and how far it is from ours (issue 18).
///
/// Every time in a trajectory is its camera capture's (DESIGN rule 1): the clock of the host
/// that stamps the frames — the one publishing CAMERA_LEFT (sg-camera-sim, or sg-vision
/// publishing its cameras' images), or else the one publishing OBJECT_POSITION (sg-vision reading
/// its cameras itself). sg-grasp times the close on its own clock, so an offset Δ between the two
/// moves every interception by Δ: at 0.8 s, every track looked stale and every grasp failed.
/// CaptureClock finds that host from the processes' PROCESS_STATUS (which channels each
/// publishes) and its offset from the heartbeats' NTP-style exchange (sg::ClockSync), so
/// sg::grasp::GraspNode can put the forecast on this host's clock.
///
///     sg::grasp::CaptureClock capture;
///     const auto o = capture.estimate(watch, *bus.clock_sync(), my_host);
///     if (o.usable) node.set_capture_clock_offset(o.offset_us);
///     else if (!o.why.empty()) spdlog::warn("{}", o.why);

#include <cstdint>
#include <string>

#include "common/clock_sync.hpp"
#include "common/process_watch.hpp"

namespace sg::grasp {

class CaptureClock {
 public:
  /// Largest error bound (µs) of an offset that is applied: a bound beyond it would move the
  /// close by more than the correction is worth.
  static constexpr int64_t kMaxError = 5'000;

  struct Estimate {
    bool usable = false;    ///< apply offset_us
    int64_t offset_us = 0;  ///< the capture clock minus ours
    int64_t error_us = -1;  ///< the bound on it
    std::string host;       ///< the capture clock's host ("" when none is known)
    std::string source;     ///< the process that told: "sg-camera-sim@lab1:77 (CAMERA_LEFT)"
    /// Why not usable when it matters ("" when the capture host is ours or not yet known):
    /// "capture clock on lab1: no clock exchange with it yet".
    std::string why;
  };

  /// The capture clock's offset: its host from `watch`, its offset from `sync` (the peer on that
  /// host with the smallest error bound). On `self_host` itself the offset is 0.
  static Estimate estimate(const ProcessWatch& watch, const ClockSync& sync,
                           const std::string& self_host);
};

}  // namespace sg::grasp
