#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace sg::vision {

/// The sums of B, G and R over `n` BGR pixels (a run of the object's colour, for its region's
/// mean colour), a vector of pixels a step in SIMD lanes (Highway, the instruction set chosen at
/// run time). `readable`: pixels that may be read from `bgr` (at least n; the rest of the image
/// row), so the last vector is read in place rather than copied.
///
///     const auto [b, g, r] = channel_sums(row + 3 * x0, x1 - x0, image.cols - x0);
std::array<uint64_t, 3> channel_sums(const uint8_t* bgr, size_t n, size_t readable);

/// channel_sums() added to *b, *g, *r (no array returned through memory for the caller to load
/// back: the hot path of run labelling).
void add_channel_sums(const uint8_t* bgr, size_t n, size_t readable, int64_t* b, int64_t* g,
                      int64_t* r);

}  // namespace sg::vision
