#include "common/latency_record.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sg {

LatencyRecord::LatencyRecord(size_t capacity) : ring_(std::max<size_t>(1, capacity)) {}

void LatencyRecord::add(int64_t us) { ring_[count_++ % ring_.size()] = us; }

std::vector<int64_t> LatencyRecord::kept() const {
  const size_t n = static_cast<size_t>(std::min<uint64_t>(count_, ring_.size()));
  return {ring_.begin(), ring_.begin() + static_cast<std::ptrdiff_t>(n)};
}

int64_t LatencyRecord::percentile(double p) const {
  if (!(p > 0 && p <= 1)) throw std::invalid_argument("percentile: p must be in (0, 1]");
  std::vector<int64_t> v = kept();
  if (v.empty()) return 0;
  const size_t rank = static_cast<size_t>(std::ceil(p * static_cast<double>(v.size())));
  const auto nth = v.begin() + static_cast<std::ptrdiff_t>(std::max<size_t>(rank, 1) - 1);
  std::nth_element(v.begin(), nth, v.end());
  return *nth;
}

std::string LatencyRecord::summary() const {
  if (count_ == 0) return "no samples";
  return "p50 " + std::to_string(percentile(0.5)) + " us, p99 " + std::to_string(percentile(0.99)) +
         " us, max " + std::to_string(percentile(1.0)) + " us over " + std::to_string(count_);
}

}  // namespace sg
