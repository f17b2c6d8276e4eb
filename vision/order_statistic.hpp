#pragma once

#include <cstddef>
#include <span>
#include <utility>

namespace sg::vision {

/// The index of the first of v[from, n) below `bound` (`largest` false) or above it (true); n
/// when none. In SIMD lanes (Highway, the instruction set chosen at run time).
size_t first_beyond(const float* v, size_t from, size_t n, float bound, bool largest);

/// The k-th smallest (`largest` false) or k-th largest (true) of `v`, 0-based, k < v.size(). A
/// small k, the usual case (a 2 % quantile of a few hundred pixels), keeps the k + 1 most extreme
/// in order in one pass: once k + 1 are kept, first_beyond() skips to the next value that enters
/// them, a vector of values a compare. A large k uses nth_element (and reorders v). Either way
/// the exact order statistic.
///
///     std::vector<float> r = ...;  // or any std::span<float>
///     float third_smallest = order_statistic(r, 2, false);
float order_statistic(std::span<float> v, size_t k, bool largest);

/// The q-quantile (0 <= q <= 1) of a non-empty `v`: its round(q (n - 1))-th smallest, found from
/// whichever end is nearer (the k-th smallest is the (n - 1 - k)-th largest).
float quantile_of(std::span<float> v, double q);

/// {quantile_of(v, q), quantile_of(v, 1 - q)} of finite values, both ends in one pass where
/// each is within 8 of its end: every vector of v goes through 8 or fewer min/max stages per end
/// (the most extreme values at each lane position), then the few candidates are sorted. Leaves v
/// as it was on that path.
std::pair<float, float> quantiles_of(std::span<float> v, double q);

}  // namespace sg::vision
