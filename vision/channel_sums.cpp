// channel_sums() in SIMD lanes: interleaved bytes split into B, G and R vectors, each summed in
// groups of eight into 64-bit lanes; compiled per instruction set (Highway).

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "vision/channel_sums.cpp"
#include "vision/channel_sums.hpp"

#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <cstring>

HWY_BEFORE_NAMESPACE();
namespace sg::vision {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

#if HWY_TARGET != HWY_SCALAR
/// Sums of up to 4095 pixels: per 64-bit lane, B + 2^20 G + 2^40 R of groups of eight (each
/// field under 255 * 4095 < 2^20), so one reduction gives all three.
template <class D8>
HWY_INLINE uint64_t PackedSums(D8 d8, const uint8_t* HWY_RESTRICT bgr, size_t n, size_t readable) {
  const hn::Repartition<uint64_t, D8> d64;
  const size_t lanes = hn::Lanes(d8);
  auto packed = hn::Zero(d64);
  auto add = [&](auto b, auto g, auto r) {
    packed = hn::Add(packed, hn::SumsOf8(b));
    packed = hn::Add(packed, hn::ShiftLeft<20>(hn::SumsOf8(g)));
    packed = hn::Add(packed, hn::ShiftLeft<40>(hn::SumsOf8(r)));
  };
  hn::Vec<D8> b, g, r;
  size_t i = 0;
  for (; i + lanes <= n; i += lanes) {
    hn::LoadInterleaved3(d8, bgr + 3 * i, b, g, r);
    add(b, g, r);
  }
  if (i < n) {
    // The last pixels: in place when a whole vector may be read, else through a copy (zeroed
    // only then: the hot path is a short run in place); lanes past n zeroed.
    alignas(64) uint8_t tail[3 * HWY_MAX_BYTES];
    const uint8_t* last = bgr + 3 * i;
    if (i + lanes > readable) {
      std::memset(tail, 0, sizeof tail);
      last = static_cast<const uint8_t*>(std::memcpy(tail, last, 3 * (n - i)));
    }
    hn::LoadInterleaved3(d8, last, b, g, r);
    const auto valid = hn::FirstN(d8, n - i);
    add(hn::IfThenElseZero(valid, b), hn::IfThenElseZero(valid, g), hn::IfThenElseZero(valid, r));
  }
  return hn::GetLane(hn::SumOfLanes(d64, packed));
}
#endif

void AddChannelSums(const uint8_t* HWY_RESTRICT bgr, size_t n, size_t readable,
                    int64_t* HWY_RESTRICT b, int64_t* HWY_RESTRICT g, int64_t* HWY_RESTRICT r) {
#if HWY_TARGET == HWY_SCALAR  // one lane: no groups of eight
  (void)readable;
  for (size_t i = 0; i < 3 * n; i += 3) *b += bgr[i], *g += bgr[i + 1], *r += bgr[i + 2];
#else
  constexpr size_t kChunk = 4095;  // pixels whose sums fit PackedSums's fields
  const hn::ScalableTag<uint8_t> d8;
  for (size_t i = 0; i < n; i += kChunk) {
    const uint64_t p = PackedSums(d8, bgr + 3 * i, std::min(kChunk, n - i), readable - i);
    *b += static_cast<int64_t>(p & 0xfffff), *g += static_cast<int64_t>((p >> 20) & 0xfffff);
    *r += static_cast<int64_t>(p >> 40);
  }
#endif
}

}  // namespace HWY_NAMESPACE
}  // namespace sg::vision
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sg::vision {

HWY_EXPORT(AddChannelSums);

void add_channel_sums(const uint8_t* bgr, size_t n, size_t readable, int64_t* b, int64_t* g,
                      int64_t* r) {
  if (n == 0) return;
  HWY_DYNAMIC_DISPATCH(AddChannelSums)(bgr, n, std::max(n, readable), b, g, r);
}

std::array<uint64_t, 3> channel_sums(const uint8_t* bgr, size_t n, size_t readable) {
  int64_t b = 0, g = 0, r = 0;
  add_channel_sums(bgr, n, readable, &b, &g, &r);
  return {static_cast<uint64_t>(b), static_cast<uint64_t>(g), static_cast<uint64_t>(r)};
}

}  // namespace sg::vision
#endif  // HWY_ONCE
