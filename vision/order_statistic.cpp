// Order statistics of a colour sample (color_adaptation.cpp); first_beyond() in SIMD lanes,
// compiled per instruction set (Highway) and chosen when first called.

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "vision/order_statistic.cpp"
#include "vision/order_statistic.hpp"

#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

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

}  // namespace HWY_NAMESPACE
}  // namespace sg::vision
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <algorithm>
#include <array>

namespace sg::vision {

HWY_EXPORT(FirstBeyond);

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

float quantile_of(std::span<float> v, double q) {
  const auto k = static_cast<size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  if (k <= v.size() / 2) return order_statistic(v, k, false);
  return order_statistic(v, v.size() - 1 - k, true);
}

}  // namespace sg::vision
#endif  // HWY_ONCE
