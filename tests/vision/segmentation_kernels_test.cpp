// The vectorized kernels give the reference's results bit for bit (issue 19): ColorDetector::
// classify against is_object() over every 8-bit colour, and Segmenter's run labelling against
// its pixel labelling on opencv-doc's photographs, the simulated lab and noise, window by window:
// the same regions, in the same order, with the same moments, extent, colour and masks.

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <bit>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "sim/camera_simulator.hpp"
#include "sim/real_scene.hpp"
#include "vision/channel_sums.hpp"
#include "vision/color_detector.hpp"
#include "vision/segmentation.hpp"

namespace sg::vision {
namespace {

/// Threshold sets: the shipped red, the widest, an upper bound of 1 and one of 0, a narrow one.
std::vector<ColorThresholds> threshold_sets() {
  std::vector<ColorThresholds> v(8);
  v[1] = {0, 1, 0, 1, 0, 1, 0};
  v[2] = {0.2, 1.0, 0.0, 1.0, 0.1, 0.5, 1};
  v[3] = {0.0, 0.0, 0.3, 0.7, 0.3, 0.7, 765};
  v[4] = {0.5123, 0.5189, 0.2, 0.25, 0.2, 0.3, 30};
  // r_min where the 8-bit skip's factor changes (1/2, 1, 3/2: 1/3, 1/2, 3/5) and a learned red.
  v[5] = {1.0 / 3, 1.0, 0.0, 0.3, 0.0, 0.3, 60};
  v[6] = {0.6, 0.9, 0.0, 0.3, 0.0, 0.3, 60};
  v[7] = {0.62, 0.93, 0.04, 0.26, 0.02, 0.24, 60};
  return v;
}

/// classify()'s bit for pixel i.
bool bit(const std::vector<uint64_t>& bits, size_t i) { return (bits[i / 64] >> (i % 64)) & 1; }

/// Every one of the 2^24 colours, as BGR pixels, made once for the test program.
const std::vector<uint8_t>& every_colour() {
  static const std::vector<uint8_t> bgr = [] {
    const size_t n = size_t{1} << 24;
    std::vector<uint8_t> v(3 * n);
    for (size_t i = 0; i < n; ++i) {
      v[3 * i] = static_cast<uint8_t>(i), v[3 * i + 1] = static_cast<uint8_t>(i >> 8);
      v[3 * i + 2] = static_cast<uint8_t>(i >> 16);
    }
    return v;
  }();
  return bgr;
}

/// One case per threshold set: each a fraction of ctest's time limit in the sanitized build,
/// where the eight in one case took over two minutes on a slow machine.
class ClassifyEveryColour : public ::testing::TestWithParam<size_t> {};

// Every one of the 2^24 colours, with every instruction set Highway compiled that this CPU has
// and each bound tested first: classify_rows() says what is_object() says.
TEST_P(ClassifyEveryColour, ClassifyIsIsObject) {
  const std::vector<uint8_t>& bgr = every_colour();
  const size_t n = bgr.size() / 3;
  std::vector<uint64_t> bits(n / 64), want(n / 64);
  const std::vector<int64_t> targets = hwy::SupportedAndGeneratedTargets();
  ASSERT_FALSE(targets.empty());
  const ColorThresholds t = threshold_sets().at(GetParam());
  const ColorDetector d(t);
  for (size_t i = 0; i < n; ++i) want[i / 64] |= uint64_t{d.is_object(&bgr[3 * i])} << (i % 64);
  for (const int64_t target : targets) {
    hwy::SetSupportedTargetsForTest(target);
    for (int first = 0; first < kBounds; ++first) {
      ClassifyRowsArgs rows{bgr.data(), 0, n, 1, n, bits.data(), 0, first};
      const ClassifyTally tally = d.classify_rows(rows);
      size_t wrong = 0;
      for (size_t w = 0; w < bits.size(); ++w) wrong += std::popcount(bits[w] ^ want[w]);
      EXPECT_EQ(wrong, 0u) << hwy::TargetName(target) << ", bound " << first << " first, r "
                           << t.r_min << "-" << t.r_max << ", " << tally.skipped << " skipped";
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

INSTANTIATE_TEST_SUITE_P(ColorKernels, ClassifyEveryColour,
                         ::testing::Range<size_t>(0, threshold_sets().size()));

// The tally: the vectors the first bound skipped, the others' whole rejections, and the next
// first bound: 64 pixels too dark (min_sum) then 64 too green (g > g_max), AVX-512's 64 a step
// or two to four smaller ones.
TEST(ColorKernels, ClassifyTallyCountsWholeRejections) {
  std::vector<uint8_t> bgr(3 * 128);
  for (size_t i = 0; i < 64; ++i) bgr[3 * i + 2] = 10;                          // dark red
  for (size_t i = 64; i < 128; ++i) bgr[3 * i + 1] = 200, bgr[3 * i + 2] = 100;  // green
  const ColorDetector d(ColorThresholds{});
  std::vector<uint64_t> bits(2, ~uint64_t{0});
  for (const int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    if (target == HWY_SCALAR) continue;  // one pixel a step: no skipping
    const ClassifyTally t = d.classify_rows({bgr.data(), 0, 128, 1, 128, bits.data(), 0, 2});
    const uint32_t steps = t.skipped + t.rejected_by[kMinSumBound];
    EXPECT_EQ(bits[0] | bits[1], 0u);
    EXPECT_TRUE(steps == 2 || steps == 4 || steps == 8) << hwy::TargetName(target);
    EXPECT_EQ(t.skipped, steps / 2) << hwy::TargetName(target);  // the green half
    EXPECT_EQ(t.rejected_by[2], 0u);  // skipped, so not counted again
    EXPECT_EQ(t.rejected_by[1], 0u);  // dark red passes r >= r_min; the green was skipped
    EXPECT_EQ(t.next_first_bound(2), 2) << "as many skipped as min_sum would";
    const ClassifyTally first_dark =
        d.classify_rows({bgr.data(), 0, 128, 1, 128, bits.data(), 0, kMinSumBound});
    EXPECT_EQ(first_dark.skipped, steps / 2) << hwy::TargetName(target);
    EXPECT_EQ(first_dark.rejected_by[2], steps / 2) << hwy::TargetName(target);
  }
  hwy::SetSupportedTargetsForTest(0);
}

// next_first_bound: another bound only when it would have skipped more than twice as many, and
// 4 more.
TEST(ColorKernels, NextFirstBoundNeedsAClearWinner) {
  ClassifyTally t;
  t.skipped = 10, t.rejected_by[4] = 24;
  EXPECT_EQ(t.next_first_bound(2), 2);
  t.rejected_by[4] = 25;
  EXPECT_EQ(t.next_first_bound(2), 4);
  t.skipped = 0, t.rejected_by[4] = 4;
  EXPECT_EQ(t.next_first_bound(2), 2);
}

// Rows of every length up to three vectors, with every instruction set: the last pixels read in
// place (the row goes on) and through the kernel's zeroed copy (it ends), and the bits past n,
// which must be clear.
TEST(ColorKernels, ClassifyEveryRowLength) {
  std::mt19937 rng(19);
  std::vector<uint8_t> bgr(3 * 400);
  for (uint8_t& v : bgr) v = static_cast<uint8_t>(rng());
  const ColorDetector d(threshold_sets()[1]);  // the widest: most pixels are the colour
  for (const int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (int n = 1; n <= 200; ++n) {
      for (const int readable : {n, 400}) {
        std::vector<uint64_t> bits((n + 63) / 64, ~uint64_t{0});
        d.classify(bgr.data(), n, bits.data(), readable);
        for (size_t i = 0; i < bits.size() * 64; ++i) {
          const bool want = i < static_cast<size_t>(n) && d.is_object(&bgr[3 * i]);
          ASSERT_EQ(bit(bits, i), want) << hwy::TargetName(target) << ", n " << n << ", readable "
                                        << readable << ", pixel " << i;
        }
      }
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

// channel_sums() of every run length to 200 and of 10000 pixels (more than one packed chunk),
// read in place and through the copy, with every compiled instruction set: a plain loop's sums.
TEST(ColorKernels, ChannelSumsOfEveryRunLength) {
  std::mt19937 rng(23);
  std::vector<uint8_t> bgr(3 * 10400);
  for (uint8_t& v : bgr) v = static_cast<uint8_t>(rng());
  std::vector<size_t> lengths(200);
  std::iota(lengths.begin(), lengths.end(), 1);
  lengths.push_back(10000);
  for (const int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (const size_t n : lengths) {
      std::array<uint64_t, 3> want{};
      for (size_t i = 0; i < n; ++i) {
        for (size_t c = 0; c < 3; ++c) want[c] += bgr[3 * i + c];
      }
      for (const size_t readable : {n, size_t{10400}}) {
        ASSERT_EQ(channel_sums(bgr.data(), n, readable), want)
            << hwy::TargetName(target) << ", n " << n << ", readable " << readable;
      }
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

void expect_same(const Segmentation& a, const Segmentation& b) {
  EXPECT_EQ(a.num_regions, b.num_regions);
  EXPECT_EQ(a.found, b.found);
  EXPECT_EQ(a.num_candidates, b.num_candidates);
  auto same_moments = [](const RawMoments& x, const RawMoments& y) {
    return x.m00 == y.m00 && x.m10 == y.m10 && x.m01 == y.m01 && x.m20 == y.m20 && x.m02 == y.m02 &&
           x.m11 == y.m11;
  };
  EXPECT_TRUE(same_moments(a.largest, b.largest));
  for (int k = 0; k < std::min(a.num_candidates, b.num_candidates); ++k) {
    const Region &x = a.regions[static_cast<size_t>(k)], &y = b.regions[static_cast<size_t>(k)];
    EXPECT_TRUE(same_moments(x.moments, y.moments)) << "candidate " << k;
    EXPECT_EQ(x.box(), y.box()) << "candidate " << k;
    EXPECT_EQ(x.sum_b, y.sum_b);
    EXPECT_EQ(x.sum_g, y.sum_g);
    EXPECT_EQ(x.sum_r, y.sum_r);
  }
}

/// Both kernels on `windows` of `image` with every threshold set: the same regions and masks.
/// Returns the regions seen (so a test knows it segmented something).
int compare_kernels(const cv::Mat& image, const std::vector<cv::Rect>& windows) {
  Segmenter runs(image.size(), Segmenter::Kernel::kRuns);
  Segmenter pixels(image.size(), Segmenter::Kernel::kPixels);
  int regions = 0;
  for (const ColorThresholds& t : threshold_sets()) {
    const ColorDetector d(t);
    for (const cv::Rect& w : windows) {
      SCOPED_TRACE(testing::Message() << "window " << w << ", r_min " << t.r_min);
      const Segmentation a = runs.run(image, w, d, 5), b = pixels.run(image, w, d, 5);
      expect_same(a, b);
      regions += a.num_regions;
      for (int k = 0; k < std::min(a.num_candidates, 3); ++k) {
        const cv::Mat ma = runs.mask_of(a.regions[static_cast<size_t>(k)]).clone();
        const cv::Mat mb = pixels.mask_of(b.regions[static_cast<size_t>(k)]);
        EXPECT_EQ(ma.size(), mb.size());
        if (ma.size() == mb.size()) {
          EXPECT_EQ(cv::countNonZero(ma != mb), 0) << "mask of candidate " << k;
        }
        EXPECT_EQ(runs.mask_origin(), pixels.mask_origin());
      }
    }
  }
  return regions;
}

std::vector<cv::Rect> windows_of(cv::Size s) {
  std::vector<cv::Rect> v = {{0, 0, s.width, s.height}, {1, 1, 7, 5}, {s.width - 33, 0, 33, 17}};
  std::mt19937 rng(2);
  for (int k = 0; k < 12; ++k) {
    const int w = 1 + static_cast<int>(rng() % 200), h = 1 + static_cast<int>(rng() % 200);
    v.push_back({static_cast<int>(rng() % static_cast<unsigned>(s.width)),
                 static_cast<int>(rng() % static_cast<unsigned>(s.height)), w, h});
  }
  return v;
}

// Real photographs (opencv-doc): fruits (red apples), baboon (red nose), a board, a building.
TEST(SegmentationKernels, RunsArePixelsOnPhotographs) {
  for (const std::string name : {"fruits.jpg", "baboon.jpg", "board.jpg", "building.jpg"}) {
    SCOPED_TRACE(name);
    const cv::Mat image = cv::imread(sim::opencv_data_dir() + "/" + name, cv::IMREAD_COLOR);
    ASSERT_FALSE(image.empty());
    EXPECT_GT(compare_kernels(image, windows_of(image.size())), 50);
  }
}

// The simulated lab's frames, and noise (thousands of small regions, every run shape).
TEST(SegmentationKernels, RunsArePixelsOnTheSimulatorAndNoise) {
  sim::CameraSimulator sim({});
  sim::StereoFrame f;
  sim.render(30, {}, f);
  EXPECT_GT(compare_kernels(f.image[0], windows_of(f.image[0].size())), 10);
  cv::Mat noise(240, 320, CV_8UC3);
  cv::randu(noise, 0, 255);
  EXPECT_GT(compare_kernels(noise, windows_of(noise.size())), 1000);
}

}  // namespace
}  // namespace sg::vision
