// ColorDetector::classify: the colour test of a row of pixels in SIMD lanes (Highway), compiled
// once per instruction set (SSE4, AVX2, AVX-512, ...) and chosen when first called.
//
// Each of the six bounds of eq. 8 is a test X <= floor(q S / 2^16) of an integer X against the
// high half of a 16-bit product (color_detector.hpp says why that is exactly is_object()), so a
// pixel costs 16-bit adds, six MulHigh and six compares: 16 pixels a vector with AVX2, 32 with
// AVX-512.

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "vision/color_classify.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <cstring>

#include "vision/color_detector.hpp"

HWY_BEFORE_NAMESPACE();
namespace sg::vision {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// Bits of `ok` for lanes [0, count) into `bits` at bit `at` (the words were zeroed).
template <class D, class M>
HWY_INLINE void put_bits(D d, M ok, size_t at, uint64_t* HWY_RESTRICT bits) {
  uint8_t bytes[8] = {};
  hn::StoreMaskBits(d, ok, bytes);
  uint64_t word;
  std::memcpy(&word, bytes, sizeof word);
  bits[at / 64] |= word << (at % 64);  // lanes are a power of two up to 64: never straddles
}

/// One vector of pixels: the mask of those of the object's colour.
template <class D16, class V>
HWY_INLINE auto object_lanes(D16 d16, V b, V g, V r, const ColorBounds& k) {
  const hn::RebindToSigned<D16> di;
  const V s = hn::Add(hn::Add(b, g), r);
  // X in lanes as signed (all values <= 765): Gt is signed on x86 before AVX-512.
  auto over = [&](V x, int i) {
    const V bound = hn::Or(hn::MulHigh(s, hn::Set(d16, k.q[i])), hn::Set(d16, k.always[i]));
    return hn::Gt(hn::BitCast(di, x), hn::BitCast(di, bound));
  };
  auto fail = hn::Lt(hn::BitCast(di, s), hn::Set(di, k.min_sum));
  fail = hn::Or(fail, over(r, 0));
  fail = hn::Or(fail, over(hn::Add(g, b), 1));
  fail = hn::Or(fail, over(g, 2));
  fail = hn::Or(fail, over(hn::Add(r, b), 3));
  fail = hn::Or(fail, over(b, 4));
  fail = hn::Or(fail, over(hn::Add(r, g), 5));
  return hn::RebindMask(d16, hn::Not(fail));
}

/// One row: bits[i / 64] bit i % 64 for pixel i < n (the words were zeroed); pixels up to
/// `readable` may be read.
template <class D16>
HWY_INLINE void classify_row(D16 d16, const uint8_t* HWY_RESTRICT bgr, size_t n, size_t readable,
                             uint64_t* HWY_RESTRICT bits, const ColorBounds& k) {
  const hn::Rebind<uint8_t, D16> d8;
  const size_t lanes = hn::Lanes(d16);
  hn::Vec<decltype(d8)> b8, g8, r8;
  size_t i = 0;
  for (; i + lanes <= n; i += lanes) {
    hn::LoadInterleaved3(d8, bgr + 3 * i, b8, g8, r8);
    const auto ok = object_lanes(d16, hn::PromoteTo(d16, b8), hn::PromoteTo(d16, g8),
                                 hn::PromoteTo(d16, r8), k);
    put_bits(d16, ok, i, bits);
  }
  if (i == n) return;
  // The last pixels: read in place when a whole vector may be, else through a zeroed copy (a
  // black pixel is below any min_sum, which is at least 1); lanes past n masked off.
  alignas(64) uint8_t tail[3 * 64] = {};
  const uint8_t* last = bgr + 3 * i;
  if (i + lanes > readable)
    last = static_cast<const uint8_t*>(std::memcpy(tail, last, 3 * (n - i)));
  hn::LoadInterleaved3(d8, last, b8, g8, r8);
  const auto ok =
      object_lanes(d16, hn::PromoteTo(d16, b8), hn::PromoteTo(d16, g8), hn::PromoteTo(d16, r8), k);
  put_bits(d16, hn::And(ok, hn::FirstN(d16, n - i)), i, bits);
}

void ClassifyRows(const ClassifyRowsArgs& a, const ColorBounds& k) {
  const hn::ScalableTag<uint16_t> d16;
  const size_t words = (a.width + 63) / 64;
  for (size_t y = 0; y < a.height; ++y) {
    uint64_t* bits = a.bits + y * a.words_per_row;
    std::memset(bits, 0, words * sizeof(uint64_t));
    classify_row(d16, a.bgr + y * a.stride, a.width, a.readable, bits, k);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sg::vision
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sg::vision {

HWY_EXPORT(ClassifyRows);

void ColorDetector::classify(const uint8_t* bgr, int n, uint64_t* bits, int readable) const {
  if (n <= 0) return;
  classify_rows(
      {bgr, 0, static_cast<size_t>(n), 1, static_cast<size_t>(std::max(n, readable)), bits, 0});
}

void ColorDetector::classify_rows(const ClassifyRowsArgs& rows) const {
  if (rows.width == 0 || rows.height == 0) return;
  HWY_DYNAMIC_DISPATCH(ClassifyRows)(rows, bounds_);
}

}  // namespace sg::vision
#endif  // HWY_ONCE
