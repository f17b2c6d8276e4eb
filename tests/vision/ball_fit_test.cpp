// The centre of a partly hidden ball's image (ball_fit.hpp): edge points of binary regions, and the
// circle fitted to them for whole discs, discs cut by a straight occluder edge at any angle, a
// finger's bite, the window's edge, and degenerate input, against rasterized discs whose centre
// is known.

#include "vision/ball_fit.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <new>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "tests/support/allocation_counter.hpp"

namespace sg::vision {
namespace {

/// Which pixel centres the occluder hides (true: hidden).
using Hidden = std::function<bool(double x, double y)>;

/// A rasterized disc: its pixels are those whose centre lies within r of `centre` and that
/// `hidden` and `valid` leave; the mask is the disc's box grown by 2, as a segmenter gives it.
struct Region {
  cv::Mat mask;
  cv::Point origin;
  cv::Point2d centroid;
  int area = 0;
};

Region rasterize(cv::Point2d centre, double r, const Hidden& hidden = nullptr,
                 cv::Rect valid = {0, 0, 1 << 20, 1 << 20}) {
  Region g;
  g.origin = {static_cast<int>(std::floor(centre.x - r)) - 2,
              static_cast<int>(std::floor(centre.y - r)) - 2};
  const int side = static_cast<int>(std::ceil(2 * r)) + 5;
  g.mask = cv::Mat::zeros(side, side, CV_8UC1);
  double sx = 0, sy = 0;
  for (int row = 0; row < side; ++row) {
    for (int col = 0; col < side; ++col) {
      const int x = g.origin.x + col, y = g.origin.y + row;
      const double dx = x - centre.x, dy = y - centre.y;
      if (dx * dx + dy * dy > r * r || !valid.contains({x, y}) || (hidden && hidden(x, y))) {
        continue;
      }
      g.mask.at<uint8_t>(row, col) = 255;
      sx += x, sy += y, ++g.area;
    }
  }
  if (g.area > 0) g.centroid = {sx / g.area, sy / g.area};
  return g;
}

std::vector<cv::Point2d> edge_of(const Region& g, cv::Rect valid = {0, 0, 1 << 20, 1 << 20}) {
  std::vector<cv::Point2d> edge;
  append_edge_points(g.mask, g.origin, valid, edge);
  return edge;
}

/// Distance from the centre to the occluder's straight edge that leaves `fraction` of a disc of
/// radius r visible: the visible part is {(p - c) . n <= h}, a disc minus the segment beyond h.
double cut_for_fraction(double fraction, double r) {
  double lo = -r, hi = r;
  for (int k = 0; k < 60; ++k) {
    const double h = (lo + hi) / 2;
    const double cap = r * r * std::acos(h / r) - h * std::sqrt(r * r - h * h);
    (1 - cap / (M_PI * r * r) < fraction ? lo : hi) = h;
  }
  return (lo + hi) / 2;
}

/// The share of the circle's circumference that `hidden` leaves visible.
double visible_arc(cv::Point2d c, double r, const Hidden& hidden) {
  int seen = 0;
  const int samples = 3600;
  for (int k = 0; k < samples; ++k) {
    const double t = 2 * M_PI * (k + 0.5) / samples;
    seen += !hidden(c.x + r * std::cos(t), c.y + r * std::sin(t));
  }
  return static_cast<double>(seen) / samples;
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[static_cast<size_t>(std::lround(q * (v.size() - 1)))];
}

/// A sub-pixel centre that varies from case to case (a fixed low-discrepancy sequence).
cv::Point2d centre_for(int k) {
  return {300 + std::fmod(0.6180339887 * k, 1.0), 200 + std::fmod(0.7548776662 * k, 1.0)};
}

// A 2x2 square gives its 8 edge midpoints; neighbours outside `valid` give none; a region that
// touches the mask's border still gives points there; a mask of the wrong type is refused.
TEST(EdgePoints, SquareGivesItsMidpointsAndNoneOutsideValid) {
  cv::Mat mask = cv::Mat::zeros(4, 4, CV_8UC1);
  mask(cv::Rect(1, 1, 2, 2)).setTo(255);
  const cv::Point origin(10, 20);  // the square is image pixels (11..12, 21..22)
  std::vector<cv::Point2d> edge;
  append_edge_points(mask, origin, {0, 0, 100, 100}, edge);
  const auto sorted = [](std::vector<cv::Point2d> v) {
    std::sort(v.begin(), v.end(),
              [](auto a, auto b) { return std::tie(a.x, a.y) < std::tie(b.x, b.y); });
    return v;
  };
  const std::vector<cv::Point2d> expected = {{10.5, 21}, {10.5, 22}, {11, 20.5}, {11, 22.5},
                                             {12, 20.5}, {12, 22.5}, {12.5, 21}, {12.5, 22}};
  EXPECT_EQ(sorted(edge), expected);
  edge.clear();
  append_edge_points(mask, origin, {11, 0, 100, 22}, edge);  // x >= 11, y <= 21 valid
  const std::vector<cv::Point2d> clipped = {{11, 20.5}, {12, 20.5}, {12.5, 21}};
  EXPECT_EQ(sorted(edge), clipped);
  edge.clear();
  append_edge_points(cv::Mat(2, 2, CV_8UC1, cv::Scalar(1)), {11, 21}, {0, 0, 100, 100}, edge);
  EXPECT_EQ(sorted(edge), expected);
  edge.clear();
  append_edge_points(cv::Mat(), {0, 0}, {0, 0, 100, 100}, edge);
  EXPECT_TRUE(edge.empty());
  EXPECT_THROW(append_edge_points(cv::Mat(2, 2, CV_8UC3), {0, 0}, {0, 0, 9, 9}, edge),
               std::invalid_argument);
}

// Whole discs, radius 8 to 40 px at sub-pixel centres: centre within 0.3 px, radius within
// 0.5 px, support above 0.9, nothing outside.
TEST(BallFitter, WholeDiscsGiveTheirCentreAndRadius) {
  BallFitter fitter;
  double worst_centre = 0, worst_radius = 0;
  int k = 0;
  for (double r = 8; r <= 40.01; r += 1.6) {
    for (int j = 0; j < 8; ++j, ++k) {
      const cv::Point2d c = centre_for(k);
      const BallFit f = fitter.fit(edge_of(rasterize(c, r)), BallFitParams{});
      ASSERT_TRUE(f.ok) << r << " " << c;
      const double e = cv::norm(f.centre - c);
      worst_centre = std::max(worst_centre, e),
      worst_radius = std::max(worst_radius, std::abs(f.radius - r));
      EXPECT_LE(e, 0.3) << r << " " << c;
      EXPECT_NEAR(f.radius, r, 0.5) << r << " " << c;
      EXPECT_GT(f.support, 0.9) << r << " " << c;
      EXPECT_EQ(f.outside, 0) << r << " " << c;
      EXPECT_GT(f.confidence, 0.7) << r << " " << c;
      EXPECT_EQ(f.arc, kWholeArc) << r << " " << c << std::hex << " " << f.arc;
    }
  }
  std::printf("whole discs (%d): worst centre error %.3f px, worst radius error %.3f px\n", k,
              worst_centre, worst_radius);
}

// The sectors of arc: a disc whose top half (y < centre) is hidden rests on the lower half's 32
// sectors, those of the directions atan2(dy, dx) in [0, pi), bits 32-63, give or take the one
// at each end of the cut; a quarter left of and below the centre, bits 32-47.
TEST(BallFitter, ArcMarksTheSectorsTheFitRestsOn) {
  BallFitter fitter;
  const cv::Point2d c(100.3, 80.6);
  const double r = 30;
  const BallFit half = fitter.fit(
      edge_of(rasterize(c, r, [&](double, double y) { return y < c.y; })), BallFitParams{});
  ASSERT_TRUE(half.ok);
  const uint64_t lower = 0xFFFFFFFF00000000ULL, ends = (1ULL << 32) | (1ULL << 63);
  EXPECT_EQ(half.arc & ~lower, 0u) << std::hex << half.arc;
  EXPECT_EQ(half.arc | ends, lower) << std::hex << half.arc;
  const BallFit quarter =
      fitter.fit(edge_of(rasterize(c, r, [&](double x, double y) { return y < c.y || x < c.x; })),
                 BallFitParams{}, r);
  ASSERT_TRUE(quarter.ok);
  EXPECT_EQ(quarter.arc & ~0x0000FFFF00000000ULL, 0u) << std::hex << quarter.arc;
  EXPECT_GE(std::popcount(quarter.arc), 14) << std::hex << quarter.arc;
  EXPECT_EQ(arc_sector(1, 0), 32);
  EXPECT_EQ(arc_sector(0, 1), 48);
  EXPECT_EQ(arc_sector(-1, -1e-9), 0);
  EXPECT_EQ(arc_sector(-1, 1e-9), 63);
}

// Discs with 40-60% of their area visible behind a straight occluder edge at many angles: p95
// centre error at most 1.5 px (the centroid's is printed for comparison), support near the
// visible share of the circumference.
TEST(BallFitter, HalfHiddenDiscsBehindAStraightEdge) {
  BallFitter fitter;
  std::vector<double> errors, centroid_errors, relative_centroid, support_gap;
  int k = 0;
  for (double r : {8.0, 9.5, 11.0, 13.0, 15.5, 18.0, 21.0, 25.0, 29.5, 34.0, 40.0}) {
    for (int a = 0; a < 17; ++a) {
      for (double fraction : {0.4, 0.45, 0.5, 0.55, 0.6}) {
        const cv::Point2d c = centre_for(k++);
        const double t = (a * 21.7 + 3.1) * M_PI / 180, h = cut_for_fraction(fraction, r);
        const cv::Point2d n(std::cos(t), std::sin(t));
        const Hidden hidden = [&](double x, double y) {
          return (x - c.x) * n.x + (y - c.y) * n.y > h;
        };
        const Region g = rasterize(c, r, hidden);
        const BallFit f = fitter.fit(edge_of(g), BallFitParams{});
        ASSERT_TRUE(f.ok) << r << " " << t << " " << fraction;
        errors.push_back(cv::norm(f.centre - c));
        centroid_errors.push_back(cv::norm(g.centroid - c));
        relative_centroid.push_back(centroid_errors.back() / r);
        support_gap.push_back(std::abs(f.support - visible_arc(c, r, hidden)));
        EXPECT_LE(support_gap.back(), 0.15) << r << " " << t << " " << fraction;
      }
    }
  }
  std::printf(
      "half hidden discs (%zu): fit centre error p50 %.3f p95 %.3f max %.3f px; centroid "
      "p50 %.2f p95 %.2f max %.2f px (%.2f r median); support - visible arc: mean |%.3f|, "
      "max %.3f\n",
      errors.size(), quantile(errors, 0.5), quantile(errors, 0.95), quantile(errors, 1),
      quantile(centroid_errors, 0.5), quantile(centroid_errors, 0.95), quantile(centroid_errors, 1),
      quantile(relative_centroid, 0.5),
      std::accumulate(support_gap.begin(), support_gap.end(), 0.0) / support_gap.size(),
      quantile(support_gap, 1));
  EXPECT_LE(quantile(errors, 0.95), 1.5);
}

// A finger 0.3-0.5 r wide biting into the disc (its tip inside), or crossing it whole (the
// larger piece is the region), at many angles: centre within 1.5 px.
TEST(BallFitter, DiscWithAFingersBite) {
  BallFitter fitter;
  std::vector<double> errors;
  int k = 0;
  for (double r : {8.0, 12.0, 17.0, 24.0, 32.0, 40.0}) {
    for (int a = 0; a < 12; ++a) {
      for (double tip : {-0.2, 0.2, 0.5, -10.0}) {  // -10: the finger crosses the disc
        const cv::Point2d c = centre_for(k);
        const double t = (a * 31.3 + 7) * M_PI / 180, width = (0.3 + 0.2 * (k % 5) / 4.0) * r;
        const double offset = (k % 2 ? 0.15 : -0.25) * r;
        ++k;
        const cv::Point2d v(std::cos(t), std::sin(t)), u(-v.y, v.x);
        const Hidden hidden = [&](double x, double y) {
          const double along = (x - c.x) * v.x + (y - c.y) * v.y,
                       across = (x - c.x) * u.x + (y - c.y) * u.y;
          return along >= tip * r && std::abs(across - offset) <= width / 2;
        };
        Region g = rasterize(c, r, hidden);
        if (tip < -1) {  // keep the larger piece, as a segmenter would
          cv::Mat labels, stats, centroids;
          cv::connectedComponentsWithStats(g.mask, labels, stats, centroids, 8);
          int best = 1;
          for (int l = 2; l < stats.rows; ++l) {
            if (stats.at<int>(l, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA))
              best = l;
          }
          g.mask = labels == best;
        }
        const BallFit f = fitter.fit(edge_of(g), BallFitParams{});
        ASSERT_TRUE(f.ok) << r << " " << t << " " << tip;
        errors.push_back(cv::norm(f.centre - c));
        EXPECT_LE(errors.back(), 1.5) << r << " " << t << " " << tip << " " << width / r;
      }
    }
  }
  std::printf("finger bites (%zu): centre error p50 %.3f p95 %.3f max %.3f px\n", errors.size(),
              quantile(errors, 0.5), quantile(errors, 0.95), quantile(errors, 1));
}

// A disc cut by the searched window's edge (or corner): the pixels beyond are not searched and
// give no edge points, so the arc alone places it, within 1.5 px. (A corner that leaves the centre
// 0.4 r outside both edges shows about 6% of the disc and 45 degrees of arc: left out, that arc
// places it only within about 3.5 px.)
TEST(BallFitter, DiscCutByTheWindowEdge) {
  BallFitter fitter;
  std::vector<double> errors;
  int k = 0;
  for (double r : {8.0, 12.0, 17.0, 24.0, 32.0, 40.0}) {
    for (double inset : {-0.4, -0.1, 0.2, 0.5}) {  // of r: how far the centre is inside the window
      for (int side = 0; side < 5; ++side, ++k) {
        if (side == 4 && inset < -0.3) continue;
        const cv::Point2d c = centre_for(k);
        const int e = static_cast<int>(std::lround(inset * r));
        cv::Rect valid(0, 0, 2000, 2000);
        if (side == 0 || side == 4) valid.x = static_cast<int>(c.x) - e, valid.width -= valid.x;
        if (side == 1 || side == 4) valid.y = static_cast<int>(c.y) - e, valid.height -= valid.y;
        if (side == 2) valid.width = static_cast<int>(c.x) + e + 1;
        if (side == 3) valid.height = static_cast<int>(c.y) + e + 1;
        const BallFit f =
            fitter.fit(edge_of(rasterize(c, r, nullptr, valid), valid), BallFitParams{});
        ASSERT_TRUE(f.ok) << r << " " << inset << " " << side;
        errors.push_back(cv::norm(f.centre - c));
        EXPECT_LE(errors.back(), 1.5) << r << " " << inset << " " << side;
      }
    }
  }
  std::printf("window edge (%zu): centre error p50 %.3f p95 %.3f max %.3f px\n", errors.size(),
              quantile(errors, 0.5), quantile(errors, 0.95), quantile(errors, 1));
}

// A radius hint is a soft preference: a right hint keeps the answer, a wrong one (x2.5, x0.4)
// does not pull a whole disc's circle away from the data.
TEST(BallFitter, RadiusHintIsSoft) {
  BallFitter fitter;
  const cv::Point2d c(300.3, 200.6);
  const auto edge = edge_of(rasterize(c, 20));
  for (double hint : {20.0, 50.0, 8.0, 0.0, -3.0, std::nan("")}) {
    const BallFit f = fitter.fit(edge, BallFitParams{}, hint);
    ASSERT_TRUE(f.ok) << hint;
    EXPECT_LE(cv::norm(f.centre - c), 0.3) << hint;
    EXPECT_NEAR(f.radius, 20, 0.5) << hint;
  }
}

// Degenerate input gives ok = false and no crash: nothing, 1-2 points, collinear or duplicate
// points, NaN/inf, points beyond 1e9 px, a disc smaller than min_radius, noise.
TEST(BallFitter, DegenerateInputIsNoFit) {
  BallFitter fitter;
  const BallFitParams p;
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(fitter.fit({}, p).ok);
  EXPECT_FALSE(fitter.fit({{3, 4}}, p).ok);
  EXPECT_FALSE(fitter.fit({{3, 4}, {5, 6}}, p).ok);
  std::vector<cv::Point2d> line, same(500, cv::Point2d(7, 8)), bad, noise;
  for (int i = 0; i < 300; ++i) line.emplace_back(10 + 0.5 * i, 20 + 0.25 * i);
  EXPECT_FALSE(fitter.fit(line, p).ok);
  EXPECT_FALSE(fitter.fit(same, p).ok);
  for (int i = 0; i < 50; ++i)
    bad.insert(bad.end(), {{nan, 1}, {1, inf}, {-inf, nan}, {1e300, 5}, {2e9, -3e12}});
  EXPECT_FALSE(fitter.fit(bad, p).ok);
  EXPECT_EQ(fitter.fit(bad, p).points, 0);
  BallFitParams tight = p;
  tight.min_radius = 5;
  EXPECT_FALSE(fitter.fit(edge_of(rasterize({50.2, 60.7}, 2.5)), tight).ok);
  BallFitParams zero = p;
  zero.inlier_tolerance = 0, zero.iterations = -5;
  EXPECT_FALSE(fitter.fit(edge_of(rasterize({50.2, 60.7}, 10)), zero).ok);
  uint32_t s = 12345;
  for (int i = 0; i < 2000; ++i) {
    s = s * 1664525u + 1013904223u;
    noise.emplace_back((s >> 8) % 1000 / 3.0, (s >> 20) % 700 / 7.0);
  }
  const BallFit f = fitter.fit(noise, p);  // anything, but no crash
  EXPECT_TRUE(!f.ok || (f.radius >= p.min_radius && f.radius <= p.max_radius));
}

// Bad points among good ones are skipped; a disc 1e8 px from the origin and more points than
// max_points (subsampled) still fit.
TEST(BallFitter, SkipsBadPointsSubsamplesAndHandlesLargeCoordinates) {
  const cv::Point2d c(300.3, 200.6);
  auto edge = edge_of(rasterize(c, 30));
  for (size_t i = 0; i < edge.size(); i += 7)
    edge.insert(edge.begin() + i, cv::Point2d(NAN, 1e300));
  BallFitter fitter;
  BallFit f = fitter.fit(edge, BallFitParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_LE(cv::norm(f.centre - c), 0.3);
  BallFitter small(40);
  f = small.fit(edge, BallFitParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_EQ(f.points, 40);
  EXPECT_LE(cv::norm(f.centre - c), 0.5);
  std::vector<cv::Point2d> far = edge_of(rasterize(c, 30));
  for (cv::Point2d& q : far) q += cv::Point2d(1e8, -1e8);
  f = fitter.fit(far, BallFitParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_LE(cv::norm(f.centre - (c + cv::Point2d(1e8, -1e8))), 0.3);
}

// Once constructed, fitting allocates nothing; prints the time per fit for ~200 edge points
// (not a pass/fail figure: the machine is shared).
TEST(BallFitter, FitAllocatesNothingAndItsTime) {
  const cv::Point2d c(300.3, 200.6);
  const double t = 0.7, h = cut_for_fraction(0.5, 32);
  const auto half = edge_of(rasterize(c, 32, [&](double x, double y) {
    return (x - c.x) * std::cos(t) + (y - c.y) * std::sin(t) > h;
  }));
  const auto whole = edge_of(rasterize(c, 25));
  BallFitter fitter;
  for (const auto* edge : {&half, &whole}) {
    const int runs = 4000;
    double sum = 0;
    const long before = sg::test::allocations();
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < runs; ++i) sum += fitter.fit(*edge, BallFitParams{}, 32.0).centre.x;
    const double us =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
            .count() /
        runs;
    EXPECT_EQ(sg::test::allocations() - before, 0);
    EXPECT_TRUE(std::isfinite(sum));
    std::printf("%s disc, %zu edge points: %.2f us per fit\n", edge == &half ? "half" : "whole",
                edge->size(), us);
  }
}

}  // namespace
}  // namespace sg::vision
