// ColorDetector::classify: the colour test of a row of pixels in SIMD lanes (Highway), compiled
// once per instruction set (SSE4, AVX2, AVX-512, ...) and chosen when first called.
//
// Each of the six bounds of eq. 8 is a test X <= floor(q S / 2^15) of an integer X against the
// high half of a 16-bit product (color_detector.hpp says why that is exactly is_object()), so a
// pixel costs 16-bit adds, six MulHigh and seven compares; a step is a vector of bytes (32 pixels
// with AVX2, 64 with AVX-512), each half widened to 16-bit lanes.

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

/// The bits of `ok`'s lanes, lane i at bit i.
template <class D, class M>
HWY_INLINE uint64_t mask_bits(D d, M ok) {
  uint8_t bytes[8] = {};
  hn::StoreMaskBits(d, ok, bytes);
  uint64_t word;
  std::memcpy(&word, bytes, sizeof word);
  return word;
}

/// One vector of pixels: the mask of those of the object's colour.
template <class D16, class V>
HWY_INLINE auto object_lanes(D16 d16, V b, V g, V r, const ColorBounds& k) {
  const hn::RebindToSigned<D16> di;
  const V s = hn::Add(hn::Add(b, g), r), twice_s = hn::Add(s, s);
  // X in lanes as signed (all values <= 765): Gt is signed on x86 before AVX-512.
  auto over = [&](V x, int i) {
    const V bound = hn::MulHigh(twice_s, hn::Set(d16, k.q[i]));  // floor(q S / 2^15)
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

/// One vector of bytes' worth of pixels from `bgr` (Lanes(d8), at most 64): pixel i's test at
/// bit i. The bytes are loaded whole, each half widened to 16-bit lanes.
template <class D8>
HWY_INLINE uint64_t classify_step(D8 d8, const uint8_t* HWY_RESTRICT bgr, const ColorBounds& k) {
  hn::Vec<D8> b, g, r;
  hn::LoadInterleaved3(d8, bgr, b, g, r);
#if HWY_TARGET == HWY_SCALAR  // one lane: no halves
  const hn::Rebind<uint16_t, D8> d16;
  return mask_bits(d16, object_lanes(d16, hn::PromoteTo(d16, b), hn::PromoteTo(d16, g),
                                     hn::PromoteTo(d16, r), k));
#else
  const hn::Half<D8> dh;
  const hn::Rebind<uint16_t, decltype(dh)> d16;
  const auto lower = object_lanes(d16, hn::PromoteTo(d16, hn::LowerHalf(dh, b)),
                                  hn::PromoteTo(d16, hn::LowerHalf(dh, g)),
                                  hn::PromoteTo(d16, hn::LowerHalf(dh, r)), k);
  const auto upper = object_lanes(d16, hn::PromoteTo(d16, hn::UpperHalf(dh, b)),
                                  hn::PromoteTo(d16, hn::UpperHalf(dh, g)),
                                  hn::PromoteTo(d16, hn::UpperHalf(dh, r)), k);
  return mask_bits(d16, lower) | mask_bits(d16, upper) << hn::Lanes(d16);
#endif
}

#if HWY_TARGET == HWY_SCALAR
template <class D8>
D8 half_of(D8 d8) {
  return d8;
}
#else
/// A vector of half as many bytes, for a row's last pixels.
template <class D8>
hn::Half<D8> half_of(D8) {
  return {};
}
#endif

/// One row: bits[i / 64] bit i % 64 for pixel i < n, the last word's bits past n zero; pixels up
/// to `readable` may be read. Whole vectors of bytes; the last pixels in one more where it may be
/// read in place (at a row's end: half a vector, then the rest through a copy).
template <class D8>
HWY_INLINE void classify_row(D8 d8, const uint8_t* HWY_RESTRICT bgr, size_t n, size_t readable,
                             uint64_t* HWY_RESTRICT bits, const ColorBounds& k) {
  const auto dh = half_of(d8);
  const size_t lanes = hn::Lanes(d8), half = hn::Lanes(dh);  // powers of two up to 64
  uint64_t word = 0;
  size_t i = 0;
  for (; i + lanes <= n; i += lanes) {
    word |= classify_step(d8, bgr + 3 * i, k) << (i % 64);
    if ((i + lanes) % 64 == 0) bits[i / 64] = word, word = 0;
  }
  if (i < n && i + lanes <= readable) {  // the last pixels in place, in a whole vector
    const uint64_t valid = ~uint64_t{0} >> (64 - (n - i));
    word |= (classify_step(d8, bgr + 3 * i, k) & valid) << (i % 64);
    i = n;
  }
  if (half < lanes && i + half <= n) {  // i % 64 + half < 64: no word fills
    word |= classify_step(dh, bgr + 3 * i, k) << (i % 64);
    i += half;
  }
  if (i < n) {
    // Fewer than `half` pixels: read in place when a whole half vector may be, else through a
    // zeroed copy; bits past n cleared.
    alignas(64) uint8_t tail[3 * 64];
    const uint8_t* last = bgr + 3 * i;
    if (i + half > readable) {
      std::memset(tail, 0, sizeof tail);
      last = static_cast<const uint8_t*>(std::memcpy(tail, last, 3 * (n - i)));
    }
    const uint64_t valid = ~uint64_t{0} >> (64 - (n - i));
    word |= (classify_step(dh, last, k) & valid) << (i % 64);
    i = n;
  }
  if (i % 64 != 0) bits[i / 64] = word;
}

void ClassifyRows(const ClassifyRowsArgs& a, const ColorBounds& k) {
  const hn::CappedTag<uint8_t, 64> d8;  // at most 64 pixels a step: one word of bits
  for (size_t y = 0; y < a.height; ++y) {
    classify_row(d8, a.bgr + y * a.stride, a.width, a.readable, a.bits + y * a.words_per_row, k);
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
