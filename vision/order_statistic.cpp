// Order statistics of a colour sample (color_adaptation.cpp); first_beyond() in SIMD lanes,
// compiled per instruction set (Highway) and chosen when first called.

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "vision/order_statistic.cpp"
#include "vision/order_statistic.hpp"

#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>

HWY_BEFORE_NAMESPACE();
namespace sg::vision {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

size_t FirstBeyond(const float* HWY_RESTRICT v, size_t from, size_t n, float bound, bool largest) {
  const hn::ScalableTag<float> d;
  const size_t lanes = hn::Lanes(d);
  const auto b = hn::Set(d, bound);
  size_t i = from;
  for (; i + lanes <= n; i += lanes) {
    const auto x = hn::LoadU(d, v + i);
    const intptr_t at = hn::FindFirstTrue(d, largest ? hn::Gt(x, b) : hn::Lt(x, b));
    if (at >= 0) return i + static_cast<size_t>(at);
  }
  for (; i < n; ++i) {
    if (largest ? v[i] > bound : v[i] < bound) return i;
  }
  return n;
}

#if !HWY_HAVE_SCALABLE && HWY_TARGET != HWY_SCALAR
/// The k-th smallest and the k_large-th largest (both < K) of v[0, n), finite values.
///
/// Each vector of v goes through K compare-exchange stages per end, so lane j holds in order the
/// K most extreme of the values at lane j of every vector: sorted columns, among which are the K
/// most extreme of all. A merge of the columns then pops the most extreme head k times.
template <size_t K, class D>
HWY_INLINE std::pair<float, float> LaneExtremes(D d, const float* HWY_RESTRICT v, size_t n,
                                                size_t k, size_t k_large) {
  using V = hn::Vec<D>;
  const size_t lanes = hn::Lanes(d);
  const V inf = hn::Set(d, std::numeric_limits<float>::infinity()), minus_inf = hn::Neg(inf);
  V small[K], large[K];
  for (size_t j = 0; j < K; ++j) small[j] = inf, large[j] = minus_inf;
  // One vector through the stages: y into the smallest, z into the largest.
  auto insert = [&](V y, V z) {
    for (size_t j = 0; j < K; ++j) {
      const V s = hn::Min(small[j], y), l = hn::Max(large[j], z);
      y = hn::Max(small[j], y), z = hn::Min(large[j], z);
      small[j] = s, large[j] = l;
    }
  };
  size_t i = 0;
  for (; i + lanes <= n; i += lanes) {
    const V x = hn::LoadU(d, v + i);
    insert(x, x);
  }
  if (i < n) {  // the last values; lanes past n +inf to the smallest, -inf to the largest
    alignas(64) float tail[16] = {};
    std::memcpy(tail, v + i, (n - i) * sizeof(float));
    const auto valid = hn::FirstN(d, n - i);
    const V x = hn::LoadU(d, tail);
    insert(hn::IfThenElse(valid, x, inf), hn::IfThenElse(valid, x, minus_inf));
  }
  // The merge: `pops` times, the column whose head is `extreme` moves up a row.
  auto kth = [&](V* column, size_t pops, auto extreme, V fill) {
    for (size_t p = 0; p < pops; ++p) {
      const size_t at = static_cast<size_t>(hn::FindFirstTrue(d, hn::Eq(column[0], extreme())));
      const auto lane = hn::AndNot(hn::FirstN(d, at), hn::FirstN(d, at + 1));
      for (size_t j = 0; j + 1 < K; ++j) column[j] = hn::IfThenElse(lane, column[j + 1], column[j]);
      column[K - 1] = hn::IfThenElse(lane, fill, column[K - 1]);
    }
    return hn::GetLane(extreme());
  };
  const float lo = kth(
      small, k, [&] { return hn::MinOfLanes(d, small[0]); }, inf);
  const float hi = kth(
      large, k_large, [&] { return hn::MaxOfLanes(d, large[0]); }, minus_inf);
  return {lo, hi};
}
#endif

/// {k-th smallest, k_large-th largest} of v[0, n) by LaneExtremes; false where not (more than 8
/// kept, or a target without fixed-size vectors).
bool KthExtremes(const float* HWY_RESTRICT v, size_t n, size_t k, size_t k_large,
                 std::pair<float, float>* out) {
#if HWY_HAVE_SCALABLE || HWY_TARGET == HWY_SCALAR
  (void)v, (void)n, (void)k, (void)k_large, (void)out;
  return false;  // arrays of vectors need a fixed size; one lane gains nothing
#else
  const hn::ScalableTag<float> d;
  if (hn::Lanes(d) > 16) return false;
  switch (std::max(k, k_large) + 1) {
    case 1:
      *out = LaneExtremes<1>(d, v, n, k, k_large);
      return true;
    case 2:
      *out = LaneExtremes<2>(d, v, n, k, k_large);
      return true;
    case 3:
      *out = LaneExtremes<3>(d, v, n, k, k_large);
      return true;
    case 4:
      *out = LaneExtremes<4>(d, v, n, k, k_large);
      return true;
    case 5:
      *out = LaneExtremes<5>(d, v, n, k, k_large);
      return true;
    case 6:
      *out = LaneExtremes<6>(d, v, n, k, k_large);
      return true;
    case 7:
      *out = LaneExtremes<7>(d, v, n, k, k_large);
      return true;
    case 8:
      *out = LaneExtremes<8>(d, v, n, k, k_large);
      return true;
    default:
      return false;
  }
#endif
}

}  // namespace HWY_NAMESPACE
}  // namespace sg::vision
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <algorithm>
#include <array>

namespace sg::vision {

HWY_EXPORT(FirstBeyond);
HWY_EXPORT(KthExtremes);

size_t first_beyond(const float* v, size_t from, size_t n, float bound, bool largest) {
  return HWY_DYNAMIC_DISPATCH(FirstBeyond)(v, from, n, bound, largest);
}

float order_statistic(std::span<float> v, size_t k, bool largest) {
  constexpr size_t kSmall = 16;
  auto before = [largest](float a, float b) { return largest ? a > b : a < b; };
  if (k >= kSmall) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end(), before);
    return v[k];
  }
  std::array<float, kSmall> best{};
  const size_t n = v.size();
  size_t i = std::min(n, k + 1);
  std::copy(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), best.begin());
  std::sort(best.begin(), best.begin() + static_cast<std::ptrdiff_t>(i), before);
  // best[0, k]: the k + 1 most extreme so far, in order; a value enters when before best[k].
  for (i = first_beyond(v.data(), i, n, best[k], largest); i < n;
       i = first_beyond(v.data(), i + 1, n, best[k], largest)) {
    size_t j = k;
    for (; j > 0 && before(v[i], best[j - 1]); --j) best[j] = best[j - 1];
    best[j] = v[i];
  }
  return best[k];
}

namespace {

/// round(q (n - 1)): the sorted index of v's q-quantile.
size_t quantile_index(size_t n, double q) {
  return static_cast<size_t>(q * static_cast<double>(n - 1) + 0.5);
}

}  // namespace

float quantile_of(std::span<float> v, double q) {
  const size_t k = quantile_index(v.size(), q);
  if (k <= v.size() / 2) return order_statistic(v, k, false);
  return order_statistic(v, v.size() - 1 - k, true);
}

std::pair<float, float> quantiles_of(std::span<float> v, double q) {
  const size_t n = v.size();
  const size_t low = quantile_index(n, q), high = n - 1 - quantile_index(n, 1 - q);
  std::pair<float, float> both;
  if (HWY_DYNAMIC_DISPATCH(KthExtremes)(v.data(), n, low, high, &both)) return both;
  return {quantile_of(v, q), quantile_of(v, 1 - q)};
}

}  // namespace sg::vision
#endif  // HWY_ONCE
