#pragma once

/// Messages in and out per channel, for a process's PROCESS_STATUS (issue 18): what `sg-lab
/// status` shows as rates in and out.
///
///     sg::ChannelRates rates;
///     rates.received("OBJECT_POSITION");      // from the bus's dispatch
///     rates.sent("OBJECT_TRAJECTORY");        // from publish
///     rates.fill(status, clock.now());        // counts, and rates since the last fill
///
/// Any host can send on any channel name, so the table is bounded: the first kMaxChannels - 1
/// channels get a row each, every later one is counted in the row "(other)".

#include <cstdint>
#include <string>
#include <vector>

#include "stereograsp/process_status_t.hpp"

namespace sg {

class ChannelRates {
 public:
  /// Rows a status holds, "(other)" included (process_status_t's bound).
  static constexpr size_t kMaxChannels = 64;
  static constexpr const char* kOther = "(other)";

  void received(const std::string& channel) { ++row(channel).in; }
  void sent(const std::string& channel) { ++row(channel).out; }

  /// Writes every row into `status` (channel, messages_in/out, rate_in_hz/rate_out_hz,
  /// num_channels); the rates are over the time since the previous fill (`now`, seconds on a
  /// monotonic clock), 0 on the first.
  void fill(stereograsp::process_status_t& status, double now);

 private:
  struct Row {
    std::string channel;
    int64_t in = 0, out = 0;
    int64_t in_before = 0, out_before = 0;  // at the previous fill
  };
  Row& row(const std::string& channel);

  std::vector<Row> rows_;
  double last_fill_ = -1;
};

}  // namespace sg
