#pragma once

/// The publication rule of the status channels (ARM_STATUS, GRASP_STATUS): on every change and
/// otherwise once a period, so a listener hears at once of a change and never waits longer than
/// a period. sg-arm-driver and the in-process trials use this one rule.
///
///     ChangeOrPeriod rule(1.0 / 20);                         // 20 Hz at rest
///     auto [status, version] = driver.status();
///     if (rule.due(version, clock.now())) bus.publish("ARM_STATUS", status);

#include <cstdint>

namespace sg {

class ChangeOrPeriod {
 public:
  /// `period` in seconds (> 0).
  explicit ChangeOrPeriod(double period) : period_(period) {}

  /// True when `version` differs from the last published one, the period has passed since the
  /// last publication, or time went back; then `now` (seconds) counts as published.
  bool due(uint64_t version, double now) {
    const bool due =
        !published_ || version != version_ || now >= last_ + period_ || now < last_;
    if (due) {
      published_ = true;
      version_ = version;
      last_ = now;
    }
    return due;
  }

 private:
  double period_;
  bool published_ = false;
  uint64_t version_ = 0;
  double last_ = 0;
};

}  // namespace sg
