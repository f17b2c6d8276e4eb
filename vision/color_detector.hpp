#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>

namespace sg::vision {

/// The object's colour as ranges of normalized RGB (eq. 7): r = R/(R+G+B), g = G/(R+G+B),
/// b = B/(R+G+B), each within [min, max], and R+G+B at least `min_intensity` (below it the
/// chromaticity of a dark pixel is noise).
struct ColorThresholds {
  double r_min = 0.40, r_max = 1.0;
  double g_min = 0.0, g_max = 0.30;
  double b_min = 0.0, b_max = 0.30;
  int min_intensity = 60;  ///< floor on R+G+B (0..765)

  /// Ranges that hold the central `keep` fraction of a sample's pixels per band (so a highlight
  /// or an edge pixel in the sample does not widen them), learned from the pixels of `bgr`
  /// (CV_8UC3) inside `roi`, widened by `margin` on each side.
  static ColorThresholds learn(const cv::Mat& bgr, const cv::Rect& roi, double margin = 0.04,
                               double keep = 0.90);
};

/// ColorDetector's bounds as classify()'s SIMD lanes use them. Each bound of eq. 8 is
/// X <= floor(q S / 2^15), S = B+G+R, X an integer: an upper bound r <= r_max is X = R with
/// q = round(2^15 r_max); a lower one, r >= r_min, is the same as (G+B) 2^15 <= (2^15 - q_min) S,
/// so X = G+B with q = 2^15 - round(2^15 r_min). With S < 2^10 and q <= 2^15 (a bound that
/// always holds included), floor(q S / 2^15) = floor(q (2 S) / 2^16) is the high half of one
/// unsigned 16-bit product. Order: R, G+B, G, R+B, B, R+G.
struct ColorBounds {
  uint16_t q[6] = {};
  int16_t min_sum = 1;  ///< R+G+B below it fails (at most 766: never)
};

/// The bounds of ColorBounds by number: 0-5 its q in order, kMinSumBound R+G+B >= min_sum.
inline constexpr int kBounds = 7, kMinSumBound = 6;

/// A block of rows for ColorDetector::classify_rows: `height` rows of `width` BGR pixels,
/// `stride` bytes apart from `bgr`, each readable to pixel `readable` (>= width), their bits in
/// rows of `words_per_row` 64-bit words from `bits`. Each vector of pixels is first tested
/// against bound `first_bound` alone and skipped when it rejects them all (the result does not
/// depend on it; the speed does: the bound that rejects most of the scene's background first).
struct ClassifyRowsArgs {
  const uint8_t* bgr;
  size_t stride, width, height, readable;
  uint64_t* bits;
  size_t words_per_row;
  int first_bound = 2;  ///< 0..kBounds-1; G <= g_max: a lab's grey, wooden and green surfaces
};

/// What classify_rows saw, to choose the next call's first bound: the vectors of pixels (up to
/// 64) that the first bound rejected whole, and among the others with no pixel of the colour,
/// how many each bound would have rejected whole.
struct ClassifyTally {
  uint32_t skipped = 0;
  uint32_t rejected_by[kBounds] = {};

  /// The bound to test first next time: the one that would have skipped the most, when it
  /// beats the current one's skips clearly (twice, and by 4: no flapping between two).
  int next_first_bound(int current) const;
};

/// The paper's threshold (eq. 8) on normalized RGB (eq. 7), in integer arithmetic with no
/// division: r >= r_min  <=>  2^15 R >= round(2^15 r_min) (R+G+B) (thresholds to 2^-15, 3e-5).
///
///     ColorDetector red(thresholds);
///     if (red.is_object(pixel)) ...     // pixel: const uint8_t* B, G, R
class ColorDetector {
 public:
  explicit ColorDetector(const ColorThresholds& t);

  bool is_object(const uint8_t* bgr) const {
    const int64_t b = bgr[0], g = bgr[1], r = bgr[2];
    const int64_t sum = b + g + r;
    if (sum < min_sum_) return false;
    // The bounds that reject most of a lab's pixels first: grey and wooden surfaces fail r >= r_min
    // or g <= g_max.
    return r * kOne >= r_lo_ * sum && g * kOne <= g_hi_ * sum && b * kOne <= b_hi_ * sum &&
           r * kOne <= r_hi_ * sum && g * kOne >= g_lo_ * sum && b * kOne >= b_lo_ * sum;
  }

  /// is_object() of `n` pixels at once, as bits: bit i % 64 of bits[i / 64] is set for the
  /// object's colour; the ceil(n / 64) words are all written (bits past n clear). The bounds as
  /// ColorBounds in 16-bit SIMD lanes (Highway: SSE4, AVX2 or AVX-512, whichever the CPU has; a
  /// vector of bytes loaded at a time, each half widened),
  /// bit for bit is_object() (a test, over every colour and every compiled instruction set).
  /// `readable`: pixels that may be read from `bgr` (at least n; the rest of an image's row), so
  /// the last vector is read in place rather than copied.
  void classify(const uint8_t* bgr, int n, uint64_t* bits, int readable = 0) const;
  /// classify() of a block of rows (a search window) in one call.
  ClassifyTally classify_rows(const ClassifyRowsArgs& rows) const;

  const ColorThresholds& thresholds() const { return t_; }

 private:
  static constexpr int64_t kOne = 1 << 15;
  ColorThresholds t_;
  int64_t r_lo_, r_hi_, g_lo_, g_hi_, b_lo_, b_hi_, min_sum_;
  ColorBounds bounds_;
};

}  // namespace sg::vision
