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

std::array<uint64_t, 3> ChannelSums(const uint8_t* HWY_RESTRICT bgr, size_t n, size_t readable) {
#if HWY_TARGET == HWY_SCALAR  // one lane: no groups of eight
  (void)readable;
  std::array<uint64_t, 3> s{};
  for (size_t i = 0; i < 3 * n; i += 3) s[0] += bgr[i], s[1] += bgr[i + 1], s[2] += bgr[i + 2];
  return s;
#else
  const hn::ScalableTag<uint8_t> d8;
  const hn::Repartition<uint64_t, decltype(d8)> d64;
  const size_t lanes = hn::Lanes(d8);
  auto sb = hn::Zero(d64), sg = hn::Zero(d64), sr = hn::Zero(d64);
  hn::Vec<decltype(d8)> b, g, r;
  size_t i = 0;
  for (; i + lanes <= n; i += lanes) {
    hn::LoadInterleaved3(d8, bgr + 3 * i, b, g, r);
    sb = hn::Add(sb, hn::SumsOf8(b)), sg = hn::Add(sg, hn::SumsOf8(g));
    sr = hn::Add(sr, hn::SumsOf8(r));
  }
  if (i < n) {
    // The last pixels: in place when a whole vector may be read, else through a copy; lanes past
    // n zeroed.
    alignas(64) uint8_t tail[3 * 64 * 4] = {};  // lanes <= 256 (any Highway target's u8 vector)
    const uint8_t* last = bgr + 3 * i;
    if (i + lanes > readable || lanes > 256) {
      last = static_cast<const uint8_t*>(std::memcpy(tail, last, 3 * (n - i)));
    }
    hn::LoadInterleaved3(d8, last, b, g, r);
    const auto valid = hn::FirstN(d8, n - i);
    sb = hn::Add(sb, hn::SumsOf8(hn::IfThenElseZero(valid, b)));
    sg = hn::Add(sg, hn::SumsOf8(hn::IfThenElseZero(valid, g)));
    sr = hn::Add(sr, hn::SumsOf8(hn::IfThenElseZero(valid, r)));
  }
  return {hn::GetLane(hn::SumOfLanes(d64, sb)), hn::GetLane(hn::SumOfLanes(d64, sg)),
          hn::GetLane(hn::SumOfLanes(d64, sr))};
#endif
}

}  // namespace HWY_NAMESPACE
}  // namespace sg::vision
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sg::vision {

HWY_EXPORT(ChannelSums);

std::array<uint64_t, 3> channel_sums(const uint8_t* bgr, size_t n, size_t readable) {
  if (n == 0) return {};
  return HWY_DYNAMIC_DISPATCH(ChannelSums)(bgr, n, std::max(n, readable));
}

}  // namespace sg::vision
#endif  // HWY_ONCE
