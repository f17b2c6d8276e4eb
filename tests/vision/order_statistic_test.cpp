// order_statistic and quantile_of against a sorted copy (std::sort, an independent answer): every
// k of vectors of every size up to 300, with and without repeated values.

#include "vision/order_statistic.hpp"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <random>
#include <string>

namespace sg::vision {
namespace {

/// `n` values, from only `distinct` different ones (so some repeat when distinct < n).
std::vector<float> values(size_t n, int distinct, std::mt19937& rng) {
  std::uniform_int_distribution<int> pick(0, distinct - 1);
  std::vector<float> v(n);
  for (float& x : v) x = static_cast<float>(pick(rng)) / static_cast<float>(distinct);
  return v;
}

// Every k, from either end (the one-pass path below 16, nth_element above): the sorted copy's.
TEST(OrderStatistic, EveryKIsTheSortedCopys) {
  std::mt19937 rng(7);
  for (size_t n = 1; n <= 300; n += (n < 40 ? 1 : 13)) {
    for (const int distinct : {3, 1000000}) {
      const std::vector<float> v = values(n, distinct, rng);
      std::vector<float> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      for (size_t k = 0; k < n; ++k) {
        std::vector<float> a = v, b = v;
        ASSERT_EQ(order_statistic(a, k, false), sorted[k]) << n << " " << k;
        ASSERT_EQ(order_statistic(b, k, true), sorted[n - 1 - k]) << n << " " << k;
      }
    }
  }
}

// quantile_of(v, q) is the round(q (n - 1))-th of the sorted copy, for q near 0, near 1 and
// between.
TEST(OrderStatistic, QuantileIsTheSortedCopys) {
  std::mt19937 rng(8);
  for (const size_t n : {1, 2, 5, 49, 150, 151, 1000}) {
    const std::vector<float> v = values(n, 1000, rng);
    std::vector<float> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    for (const double q : {0.0, 0.02, 0.1, 0.5, 0.9, 0.98, 1.0}) {
      std::vector<float> a = v;
      const auto k = static_cast<size_t>(std::lround(q * static_cast<double>(n - 1)));
      EXPECT_EQ(quantile_of(a, q), sorted[k]) << "n " << n << ", q " << q;
    }
  }
}

/// quantiles_of(a copy of v, q) against the sorted copy, for q near an end and q = 0.1, v of
/// every length up to 70 and some to 400, with few and with many distinct values: the first
/// case where they differ, "" when none does.
std::string first_quantile_mismatch() {
  std::mt19937 rng(9);
  for (size_t n = 1; n <= 400; n += (n < 70 ? 1 : 11)) {
    for (const int distinct : {2, 50, 1000000}) {
      const std::vector<float> v = values(n, distinct, rng);
      std::vector<float> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      for (const double q : {0.0, 0.01, 0.02, 0.05, 0.1}) {
        std::vector<float> a = v;
        const auto [lo, hi] = quantiles_of(a, q);
        const auto k = static_cast<size_t>(q * static_cast<double>(n - 1) + 0.5);
        const auto k_hi = static_cast<size_t>((1 - q) * static_cast<double>(n - 1) + 0.5);
        if (lo != sorted[k] || hi != sorted[k_hi]) {
          return "n " + std::to_string(n) + ", q " + std::to_string(q) + ": " + std::to_string(lo) +
                 ", " + std::to_string(hi) + " against " + std::to_string(sorted[k]) + ", " +
                 std::to_string(sorted[k_hi]);
        }
      }
    }
  }
  return "";
}

// quantiles_of(v, q) is both ends' quantile_of, with every compiled instruction set: on the lane
// path (q near an end: every length around the vector sizes, up to the largest kept set) and off
// it (q = 0.1 of 300 values).
TEST(OrderStatistic, QuantilesAreTheSortedCopys) {
  for (const int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    EXPECT_EQ(first_quantile_mismatch(), "") << hwy::TargetName(target);
  }
  hwy::SetSupportedTargetsForTest(0);
}

}  // namespace
}  // namespace sg::vision
