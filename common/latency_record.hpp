#pragma once

/// A process's own latencies (microseconds), kept for the percentiles it reports when it ends:
/// the newest `capacity` samples in a ring, so a week-long run holds a bounded amount (issue 19:
/// sg-vision's "second image received -> OBJECT_POSITION published").
///
///     LatencyRecord pair_to_position(1 << 16);
///     pair_to_position.add(published_utime - second_image_recv_utime);
///     std::puts(pair_to_position.summary().c_str());  // "p50 412 us, p99 731 us, max 1203 us
///                                                      //  over 2400"
///
/// Percentiles are the nearest-rank ones of the samples kept (the p-th: sorted[ceil(p n) - 1]).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sg {

class LatencyRecord {
 public:
  explicit LatencyRecord(size_t capacity = size_t{1} << 16);

  void add(int64_t us);
  /// Samples added in all (more than capacity() when the oldest were dropped).
  uint64_t count() const { return count_; }
  size_t capacity() const { return ring_.size(); }
  /// The nearest-rank `p` percentile (0 < p <= 1) of the samples kept; 0 without any.
  int64_t percentile(double p) const;
  /// "p50 A us, p99 B us, max C us over N" ("no samples" without any).
  std::string summary() const;

 private:
  std::vector<int64_t> kept() const;
  std::vector<int64_t> ring_;
  uint64_t count_ = 0;
};

}  // namespace sg
