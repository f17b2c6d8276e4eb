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

/// A vector of pixels in 16-bit lanes, with S = B+G+R.
template <class V>
struct Pixels {
  V b, g, r, s;
};

template <class D16, class V>
HWY_INLINE Pixels<V> pixels(D16, V b, V g, V r) {
  return {b, g, r, hn::Add(hn::Add(b, g), r)};
}

/// The X of bound i: R, G+B, G, R+B, B, R+G.
template <int i, class V>
HWY_INLINE V bounded(const Pixels<V>& p) {
  if constexpr (i == 0) return p.r;
  if constexpr (i == 1) return hn::Add(p.g, p.b);
  if constexpr (i == 2) return p.g;
  if constexpr (i == 3) return hn::Add(p.r, p.b);
  if constexpr (i == 4) return p.b;
  return hn::Add(p.r, p.g);
}

/// The lanes that fail bound i (ColorBounds's numbering): X > floor(q S / 2^15), or S < min_sum.
/// X in lanes as signed (all values <= 765): Gt is signed on x86 before AVX-512.
template <int i, class D16, class V>
HWY_INLINE auto fails(D16 d16, const Pixels<V>& p, const ColorBounds& k) {
  const hn::RebindToSigned<D16> di;
  if constexpr (i == kMinSumBound) {
    return hn::Lt(hn::BitCast(di, p.s), hn::Set(di, k.min_sum));
  } else {
    const V x = bounded<i>(p);
    const V bound = hn::MulHigh(hn::Add(p.s, p.s), hn::Set(d16, k.q[i]));  // floor(q S / 2^15)
    return hn::Gt(hn::BitCast(di, x), hn::BitCast(di, bound));
  }
}

/// One vector of pixels: the mask of those of the object's colour.
template <class D16, class V>
HWY_INLINE auto object_lanes(D16 d16, const Pixels<V>& p, const ColorBounds& k) {
  auto fail = hn::Or(fails<kMinSumBound>(d16, p, k), fails<0>(d16, p, k));
  fail = hn::Or(fail, fails<1>(d16, p, k));
  fail = hn::Or(fail, fails<2>(d16, p, k));
  fail = hn::Or(fail, fails<3>(d16, p, k));
  fail = hn::Or(fail, fails<4>(d16, p, k));
  fail = hn::Or(fail, fails<5>(d16, p, k));
  return hn::RebindMask(d16, hn::Not(fail));
}

/// For a vector of pixels none of which is the colour (its halves lo and hi): the bounds that
/// reject every one.
template <class D16, class V>
HWY_NOINLINE void tally_rejections(D16 d16, const Pixels<V>& lo, const Pixels<V>& hi,
                                   const ColorBounds& k, ClassifyTally& tally) {
  const hn::RebindToSigned<D16> di;
  auto whole = [&](auto a, auto b) { return hn::AllTrue(di, hn::And(a, b)) ? 1u : 0u; };
  tally.rejected_by[0] += whole(fails<0>(d16, lo, k), fails<0>(d16, hi, k));
  tally.rejected_by[1] += whole(fails<1>(d16, lo, k), fails<1>(d16, hi, k));
  tally.rejected_by[2] += whole(fails<2>(d16, lo, k), fails<2>(d16, hi, k));
  tally.rejected_by[3] += whole(fails<3>(d16, lo, k), fails<3>(d16, hi, k));
  tally.rejected_by[4] += whole(fails<4>(d16, lo, k), fails<4>(d16, hi, k));
  tally.rejected_by[5] += whole(fails<5>(d16, lo, k), fails<5>(d16, hi, k));
  tally.rejected_by[6] += whole(fails<6>(d16, lo, k), fails<6>(d16, hi, k));
}

#if HWY_TARGET != HWY_SCALAR
/// A vector of bytes' worth of pixels (Lanes(d8)) from `bgr`, its two halves widened to 16-bit
/// lanes: the bytes split into B, G and R vectors (LoadInterleaved3's shuffles), each half
/// zero-extended.
template <class D8, class V16>
HWY_INLINE void widened(D8 d8, const uint8_t* HWY_RESTRICT bgr, Pixels<V16>& lo, Pixels<V16>& hi) {
  const hn::Half<D8> dh;
  const hn::Rebind<uint16_t, decltype(dh)> d16;
  hn::Vec<D8> b, g, r;
  hn::LoadInterleaved3(d8, bgr, b, g, r);
  lo = pixels(d16, hn::PromoteTo(d16, hn::LowerHalf(dh, b)),
              hn::PromoteTo(d16, hn::LowerHalf(dh, g)), hn::PromoteTo(d16, hn::LowerHalf(dh, r)));
  hi = pixels(d16, hn::PromoteTo(d16, hn::UpperHalf(dh, b)),
              hn::PromoteTo(d16, hn::UpperHalf(dh, g)), hn::PromoteTo(d16, hn::UpperHalf(dh, r)));
}
#endif

#if HWY_TARGET == HWY_AVX3_DL
/// vpermt2b's byte indices: for half h, channel c, output byte 2i the byte of pixel 32h + i
/// (3 (32h + i) + c) in the two vectors from byte 64h; odd bytes (zeroed by the mask) 0.
struct WidenIndices {
  alignas(64) uint8_t of[2][3][64];
};
constexpr WidenIndices widen_indices() {
  WidenIndices w{};
  for (int h = 0; h < 2; ++h) {
    for (int c = 0; c < 3; ++c) {
      for (int i = 0; i < 32; ++i) w.of[h][c][2 * i] = static_cast<uint8_t>(3 * i + c + 32 * h);
    }
  }
  return w;
}
inline constexpr WidenIndices kWidenIndices = widen_indices();

/// With AVX-512 VBMI, 64 pixels: each half's B, G and R as 16-bit lanes in one byte permutation
/// of two vectors of the interleaved bytes (vpermt2b, the high bytes zeroed by the mask),
/// six instructions for LoadInterleaved3's dozen shuffles and the six widenings.
template <class V16>
HWY_INLINE void widened(hn::Simd<uint8_t, 64, 0>, const uint8_t* HWY_RESTRICT bgr,
                        Pixels<V16>& lo, Pixels<V16>& hi) {
  const hn::Simd<uint16_t, 32, 0> d16;
  const __m512i a = _mm512_loadu_si512(bgr), b = _mm512_loadu_si512(bgr + 64),
                c = _mm512_loadu_si512(bgr + 128);
  constexpr __mmask64 kLowBytes = 0x5555555555555555ull;
  auto pick = [&](int h, int ch, __m512i x, __m512i y) {
    const __m512i idx = _mm512_load_si512(kWidenIndices.of[h][ch]);
    return V16{_mm512_maskz_permutex2var_epi8(kLowBytes, x, idx, y)};
  };
  lo = pixels(d16, pick(0, 0, a, b), pick(0, 1, a, b), pick(0, 2, a, b));
  hi = pixels(d16, pick(1, 0, b, c), pick(1, 1, b, c), pick(1, 2, b, c));
}
#endif

/// One vector of bytes' worth of pixels from `bgr` (Lanes(d8), at most 64): pixel i's test at
/// bit i. The bytes are loaded whole, each half widened to 16-bit lanes; bound kFirst alone
/// first, the rest only when some pixel passes it.
template <int kFirst, class D8>
HWY_INLINE uint64_t classify_step(D8 d8, const uint8_t* HWY_RESTRICT bgr, const ColorBounds& k,
                                  ClassifyTally& tally) {
#if HWY_TARGET == HWY_SCALAR  // one lane: no halves
  hn::Vec<D8> b, g, r;
  hn::LoadInterleaved3(d8, bgr, b, g, r);
  const hn::Rebind<uint16_t, D8> d16;
  const auto p = pixels(d16, hn::PromoteTo(d16, b), hn::PromoteTo(d16, g), hn::PromoteTo(d16, r));
  (void)tally;
  return mask_bits(d16, object_lanes(d16, p, k));
#else
  const hn::Rebind<uint16_t, hn::Half<D8>> d16;
  const hn::RebindToSigned<decltype(d16)> di;
  Pixels<hn::Vec<decltype(d16)>> lo, hi;
  widened(d8, bgr, lo, hi);
  if (hn::AllTrue(di, hn::And(fails<kFirst>(d16, lo, k), fails<kFirst>(d16, hi, k)))) {
    ++tally.skipped;
    return 0;
  }
  const uint64_t bits = mask_bits(d16, object_lanes(d16, lo, k)) |
                        mask_bits(d16, object_lanes(d16, hi, k)) << hn::Lanes(d16);
  if (bits == 0) tally_rejections(d16, lo, hi, k, tally);
  return bits;
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
template <int kFirst, class D8>
HWY_INLINE void classify_row(D8 d8, const uint8_t* HWY_RESTRICT bgr, size_t n, size_t readable,
                             uint64_t* HWY_RESTRICT bits, const ColorBounds& k,
                             ClassifyTally& tally) {
  const auto dh = half_of(d8);
  const size_t lanes = hn::Lanes(d8), half = hn::Lanes(dh);  // powers of two up to 64
  uint64_t word = 0;
  size_t i = 0;
  for (; i + lanes <= n; i += lanes) {
    word |= classify_step<kFirst>(d8, bgr + 3 * i, k, tally) << (i % 64);
    if ((i + lanes) % 64 == 0) bits[i / 64] = word, word = 0;
  }
  if (i < n && i + lanes <= readable) {  // the last pixels in place, in a whole vector
    const uint64_t valid = ~uint64_t{0} >> (64 - (n - i));
    word |= (classify_step<kFirst>(d8, bgr + 3 * i, k, tally) & valid) << (i % 64);
    i = n;
  }
  if (half < lanes && i + half <= n) {  // i % 64 + half < 64: no word fills
    word |= classify_step<kFirst>(dh, bgr + 3 * i, k, tally) << (i % 64);
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
    word |= (classify_step<kFirst>(dh, last, k, tally) & valid) << (i % 64);
    i = n;
  }
  if (i % 64 != 0) bits[i / 64] = word;
}

template <int kFirst>
ClassifyTally classify_rows(const ClassifyRowsArgs& a, const ColorBounds& k) {
  const hn::CappedTag<uint8_t, 64> d8;  // at most 64 pixels a step: one word of bits
  ClassifyTally tally;
  for (size_t y = 0; y < a.height; ++y) {
    classify_row<kFirst>(d8, a.bgr + y * a.stride, a.width, a.readable,
                         a.bits + y * a.words_per_row, k, tally);
  }
  return tally;
}

ClassifyTally ClassifyRows(const ClassifyRowsArgs& a, const ColorBounds& k) {
  switch (a.first_bound) {
    case 0:
      return classify_rows<0>(a, k);
    case 1:
      return classify_rows<1>(a, k);
    case 3:
      return classify_rows<3>(a, k);
    case 4:
      return classify_rows<4>(a, k);
    case 5:
      return classify_rows<5>(a, k);
    case kMinSumBound:
      return classify_rows<kMinSumBound>(a, k);
    default:
      return classify_rows<2>(a, k);
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

ClassifyTally ColorDetector::classify_rows(const ClassifyRowsArgs& rows) const {
  if (rows.width == 0 || rows.height == 0) return {};
  return HWY_DYNAMIC_DISPATCH(ClassifyRows)(rows, bounds_);
}

int ClassifyTally::next_first_bound(int current) const {
  const uint32_t* best = std::max_element(rejected_by, rejected_by + kBounds);
  return *best > 2 * skipped + 4 ? static_cast<int>(best - rejected_by) : current;
}

}  // namespace sg::vision
#endif  // HWY_ONCE
