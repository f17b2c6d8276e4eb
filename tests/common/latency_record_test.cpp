// LatencyRecord: nearest-rank percentiles with known answers, and a ring that keeps only the
// newest samples.

#include "common/latency_record.hpp"

#include <gtest/gtest.h>

namespace sg {
namespace {

// 1..100 us: the p-th percentile by nearest rank is p itself; the max is 100.
TEST(LatencyRecord, NearestRankPercentiles) {
  LatencyRecord r(1000);
  for (int64_t us = 100; us >= 1; --us) r.add(us);
  EXPECT_EQ(r.percentile(0.5), 50);
  EXPECT_EQ(r.percentile(0.99), 99);
  EXPECT_EQ(r.percentile(0.001), 1);
  EXPECT_EQ(r.percentile(1.0), 100);
  EXPECT_EQ(r.summary(), "p50 50 us, p99 99 us, max 100 us over 100");
  EXPECT_THROW(r.percentile(0), std::invalid_argument);
  EXPECT_EQ(LatencyRecord(4).summary(), "no samples");
}

// A ring of 10: after 1..25, the kept samples are 16..25, and the count is all 25.
TEST(LatencyRecord, KeepsTheNewestCapacitySamples) {
  LatencyRecord r(10);
  for (int64_t us = 1; us <= 25; ++us) r.add(us);
  EXPECT_EQ(r.count(), 25u);
  EXPECT_EQ(r.percentile(0.1), 16);
  EXPECT_EQ(r.percentile(1.0), 25);
}

}  // namespace
}  // namespace sg
