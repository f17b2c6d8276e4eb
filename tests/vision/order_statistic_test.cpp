// order_statistic and quantile_of against a sorted copy (std::sort, an independent answer): every
// k of vectors of every size up to 300, with and without repeated values.

#include "vision/order_statistic.hpp"

#include <gtest/gtest.h>

#include <random>

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

}  // namespace
}  // namespace sg::vision
