// Plot (logger/plot.hpp) and the session figures (logger/session_plots.hpp): PNGs that decode,
// pixels where the data says they should be, nice ticks, and no crash on empty or odd input.

#include "logger/plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "logger/session_plots.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::logger {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A new temporary directory, removed with its contents at the end of the test (kept, to look at
// the figures, when the environment sets SG_KEEP_TEST_FILES).
struct TempDir {
  TempDir() : path(test::make_temp_dir()) {}
  ~TempDir() {
    if (std::getenv("SG_KEEP_TEST_FILES") != nullptr) return;
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  std::string path;
};

// Sum of absolute channel differences between a pixel and a BGR colour.
int distance(const cv::Vec3b& pixel, const cv::Scalar& colour) {
  int d = 0;
  for (int c = 0; c < 3; ++c) d += std::abs(pixel[c] - static_cast<int>(colour[c]));
  return d;
}

// True when a pixel within `radius` of `at` is within `tolerance` of `colour`.
bool colour_near(const cv::Mat& image, cv::Point2d at, const cv::Scalar& colour, int radius = 1,
                 int tolerance = 60) {
  const int cx = static_cast<int>(std::lround(at.x)), cy = static_cast<int>(std::lround(at.y));
  for (int y = cy - radius; y <= cy + radius; ++y) {
    for (int x = cx - radius; x <= cx + radius; ++x) {
      if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) continue;
      if (distance(image.at<cv::Vec3b>(y, x), colour) <= tolerance) return true;
    }
  }
  return false;
}

// Pixels that are not the background.
int count_non_background(const cv::Mat& image) {
  int n = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      n += distance(image.at<cv::Vec3b>(y, x), palette::kBackground) != 0;
    }
  }
  return n;
}

// Pixels exactly of `colour`.
int count_colour(const cv::Mat& image, const cv::Scalar& colour) {
  int n = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) n += distance(image.at<cv::Vec3b>(y, x), colour) == 0;
  }
  return n;
}

void expect_ticks(const std::vector<double>& actual, const std::vector<double>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(actual[i], expected[i], 1e-12) << i;
}

// Ticks step by 1, 2 or 5 times a power of ten and cover the range.
TEST(Plot, NiceTicksForKnownRanges) {
  expect_ticks(Plot::nice_ticks(0, 1), {0, 0.2, 0.4, 0.6, 0.8, 1.0});
  expect_ticks(Plot::nice_ticks(0, 7), {0, 2, 4, 6, 8});
  expect_ticks(Plot::nice_ticks(-3, 3), {-3, -2, -1, 0, 1, 2, 3});
  expect_ticks(Plot::nice_ticks(-3, 3, 5), {-4, -2, 0, 2, 4});
  expect_ticks(Plot::nice_ticks(0.12, 0.47), {0.1, 0.2, 0.3, 0.4, 0.5});
  expect_ticks(Plot::nice_ticks(0, 1000, 5), {0, 500, 1000});
  expect_ticks(Plot::nice_ticks(-0.003, 0.0011), {-0.003, -0.002, -0.001, 0, 0.001, 0.002});
  // Exact doubles: 3 * 0.2 is the double nearest 0.6, not 0.6000000000000001.
  EXPECT_EQ(Plot::nice_ticks(0, 1)[3], 0.6);
}

// A zero, reversed or non-finite range still gives at least two finite ticks around the value.
TEST(Plot, NiceTicksForDegenerateRanges) {
  for (auto [lo, hi] : std::vector<std::pair<double, double>>{
           {5, 5}, {0, 0}, {-2e-9, -2e-9}, {3, 1}, {kNaN, 1}, {0, kNaN}, {1e300, 1e300}}) {
    const std::vector<double> ticks = Plot::nice_ticks(lo, hi);
    ASSERT_GE(ticks.size(), 2u) << lo << " " << hi;
    ASSERT_LE(ticks.size(), 7u) << lo << " " << hi;
    for (double t : ticks) EXPECT_TRUE(std::isfinite(t)) << lo << " " << hi;
    EXPECT_LT(ticks.front(), ticks.back());
    if (std::isfinite(lo) && std::isfinite(hi)) {
      EXPECT_LE(ticks.front(), std::min(lo, hi));
      EXPECT_GE(ticks.back(), std::max(lo, hi));
    }
  }
}

// A known line's PNG decodes at the requested size, with the line's colour at computed pixels.
TEST(Plot, LineDrawnAtComputedPixels) {
  const TempDir temp;
  const std::string& dir = temp.path;
  Plot plot(420, 310, "y = 2x", "x", "y");
  std::vector<double> xs, ys;
  for (int i = 0; i <= 10; ++i) {
    xs.push_back(i);
    ys.push_back(2.0 * i);
  }
  plot.line(xs, ys, palette::kRed);
  const std::string path = dir + "/line.png";
  ASSERT_TRUE(plot.save(path));
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 420);
  EXPECT_EQ(image.rows, 310);

  // Ticks 0, 2, ..., 10 for x and 0, 5, ..., 20 (or similar) for y: the range is the data's.
  EXPECT_DOUBLE_EQ(plot.x_ticks().front(), 0);
  EXPECT_DOUBLE_EQ(plot.x_ticks().back(), 10);
  EXPECT_DOUBLE_EQ(plot.y_ticks().front(), 0);
  EXPECT_DOUBLE_EQ(plot.y_ticks().back(), 20);
  const cv::Rect area = plot.plot_area();
  EXPECT_NEAR(plot.pixel(0, 0).x, area.x, 1e-9);
  EXPECT_NEAR(plot.pixel(0, 0).y, area.y + area.height, 1e-9);
  EXPECT_NEAR(plot.pixel(10, 20).x, area.x + area.width, 1e-9);
  EXPECT_NEAR(plot.pixel(10, 20).y, area.y, 1e-9);

  int on_line = 0, samples = 0;
  for (double x = 0.25; x <= 9.75; x += 0.25, ++samples) {
    on_line += colour_near(image, plot.pixel(x, 2 * x), palette::kRed);
  }
  EXPECT_EQ(on_line, samples);
  EXPECT_FALSE(colour_near(image, plot.pixel(8, 4), palette::kRed, 3));
  EXPECT_FALSE(colour_near(image, plot.pixel(2, 16), palette::kRed, 3));
  EXPECT_EQ(distance(image.at<cv::Vec3b>(cv::Point(plot.pixel(8, 4))), palette::kBackground), 0);
}

// Markers, a shaded band, bars and a legend each put their colour where expected.
TEST(Plot, MarkersBandsBarsAndLegend) {
  Plot plot(600, 400, "markers", "x", "y");
  plot.shade_x(2, 3, palette::kShade, "band");
  plot.bars({0, 1, 2}, {1, 3}, palette::kGreen, "bars");
  plot.crosses({5}, {2}, palette::kBlue, "crosses", 6);
  plot.circles({7}, {1}, palette::kOrange, "circles", 6);
  plot.vline(9, palette::kPurple, "event");
  const cv::Mat image = plot.render();
  ASSERT_EQ(image.cols, 600);
  ASSERT_EQ(image.rows, 400);
  // Band: flat colour across its width at mid-height.
  EXPECT_EQ(distance(image.at<cv::Vec3b>(cv::Point(plot.pixel(2.5, 1.5))), palette::kShade), 0);
  EXPECT_GT(count_colour(image, palette::kShade), 100);
  // Bars: filled at their centre, below their count; not above it.
  EXPECT_EQ(distance(image.at<cv::Vec3b>(cv::Point(plot.pixel(1.5, 1.5))), palette::kGreen), 0);
  EXPECT_FALSE(colour_near(image, plot.pixel(0.5, 2.0), palette::kGreen, 2, 0));
  // A cross has its arms' ends 6 pixels off diagonally; a circle has its rim 6 pixels away.
  const cv::Point2d cross = plot.pixel(5, 2), circle = plot.pixel(7, 1);
  EXPECT_TRUE(colour_near(image, cross + cv::Point2d(5, 5), palette::kBlue));
  EXPECT_TRUE(colour_near(image, cross + cv::Point2d(-5, 5), palette::kBlue));
  EXPECT_TRUE(colour_near(image, circle + cv::Point2d(6, 0), palette::kOrange));
  EXPECT_TRUE(colour_near(image, circle + cv::Point2d(0, -6), palette::kOrange));
  EXPECT_FALSE(colour_near(image, circle, palette::kOrange, 2));  // open circles
  // The dashed marker.
  int dashes = 0;
  for (double y = 0.2; y < 3; y += 0.1)
    dashes += colour_near(image, plot.pixel(9, y), palette::kPurple, 0);
  EXPECT_GT(dashes, 10);
  EXPECT_LT(dashes, 28);
}

// Equal aspect makes one unit as long in x as in y; a log x axis spaces decades evenly.
TEST(Plot, EqualAspectAndLogScale) {
  Plot plane(500, 300, "plane", "X (m)", "Y (m)");
  plane.set_equal_aspect(true);
  plane.line({0, 1}, {0, 0.1}, palette::kBlue);
  const cv::Point2d o = plane.pixel(0, 0), x1 = plane.pixel(1, 0), y1 = plane.pixel(0, 1);
  EXPECT_NEAR(x1.x - o.x, o.y - y1.y, 1e-6);
  const cv::Rect area = plane.plot_area();
  EXPECT_GE(plane.pixel(0, 0.1).y, area.y);  // all data inside
  EXPECT_LE(plane.pixel(1, 0).x, area.x + area.width + 1e-9);

  Plot log(500, 300, "log", "ms", "count");
  log.set_log_x(true);
  log.bars({0.1, 1, 10, 100, 1000}, {1, 5, 2, 0}, palette::kBlue);
  EXPECT_NEAR(log.pixel(10, 0).x - log.pixel(1, 0).x, log.pixel(100, 0).x - log.pixel(10, 0).x,
              1e-6);
  const std::vector<double> ticks = log.x_ticks();
  ASSERT_EQ(ticks.size(), 5u);
  EXPECT_NEAR(ticks.front(), 0.1, 1e-12);
  EXPECT_NEAR(ticks.back(), 1000, 1e-9);
  EXPECT_GT(count_non_background(log.render()), 1000);
}

// Empty, single-point, constant, all-NaN and non-positive-on-log series render and save.
TEST(Plot, DegenerateSeriesStillSave) {
  const TempDir temp;
  const std::string& dir = temp.path;
  std::vector<Plot> plots;
  plots.emplace_back(300, 200, "empty", "x", "y");
  plots.back().line({}, {}, palette::kBlue, "nothing");
  plots.emplace_back(300, 200, "one point", "x", "y");
  plots.back().line({3}, {3}, palette::kBlue, "one");
  plots.back().crosses({3}, {3}, palette::kRed);
  plots.emplace_back(300, 200, "constant", "x", "y");
  plots.back().line({0, 1, 2}, {5, 5, 5}, palette::kBlue);
  plots.emplace_back(300, 200, "nan", "x", "y");
  plots.back().line({kNaN, 1, kNaN}, {kNaN, kNaN, 2}, palette::kBlue);
  plots.back().shade_x(kNaN, 1, palette::kShade);
  plots.emplace_back(300, 200, "log", "x", "y");
  plots.back().set_log_x(true);
  plots.back().line({-1, 0}, {1, 2}, palette::kBlue);
  plots.emplace_back(10, 10, "", "", "");  // raised to the minimum size
  plots.back().note("no data");
  for (size_t i = 0; i < plots.size(); ++i) {
    const std::string path = dir + "/plot" + std::to_string(i) + ".png";
    ASSERT_TRUE(plots[i].save(path)) << i;
    const cv::Mat image = cv::imread(path);
    ASSERT_FALSE(image.empty()) << i;
    EXPECT_GT(count_non_background(image), 100) << i;  // frame, ticks, text
    for (double t : plots[i].x_ticks()) EXPECT_TRUE(std::isfinite(t)) << i;
    for (double t : plots[i].y_ticks()) EXPECT_TRUE(std::isfinite(t)) << i;
  }
  EXPECT_EQ(cv::imread(dir + "/plot5.png").cols, 160);
  // The single point: its cross is drawn at its pixel.
  EXPECT_TRUE(colour_near(plots[1].render(), plots[1].pixel(3, 3), palette::kRed));
}

// A PNG that cannot be written throws an error that names the path.
TEST(Plot, SaveFailureNamesThePath) {
  Plot plot(200, 150, "t", "x", "y");
  const std::string path = "/nonexistent-directory/sub/plot.png";
  try {
    plot.save(path);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

// The bin edges of a Histogram: log-spaced when lo > 0 and hi / lo > 100, else linear.
TEST(SessionPlots, HistogramEdges) {
  Histogram log{0.1, 1000, std::vector<int64_t>(4, 1)};
  EXPECT_TRUE(histogram_is_log(log));
  const std::vector<double> edges = histogram_edges(log);
  ASSERT_EQ(edges.size(), 5u);
  EXPECT_NEAR(edges[0], 0.1, 1e-12);
  EXPECT_NEAR(edges[1], 1, 1e-12);
  EXPECT_NEAR(edges[2], 10, 1e-9);
  EXPECT_EQ(edges[4], 1000);
  Histogram linear{0, 100, std::vector<int64_t>(4, 1)};
  EXPECT_FALSE(histogram_is_log(linear));
  EXPECT_EQ(histogram_edges(linear), (std::vector<double>{0, 25, 50, 75, 100}));
  EXPECT_FALSE(histogram_is_log(Histogram{1, 50, {1}}));
  EXPECT_TRUE(histogram_edges(Histogram{1, 50, {}}).empty());
}

PlotData synthetic_session() {
  PlotData data;
  for (int i = 0; i < 400; ++i) {
    const double t = i * 0.05, angle = t * 0.6;
    const Eigen::Vector3d truth(0.5 + 0.15 * std::cos(angle), 0.15 * std::sin(angle), 0.1);
    data.truth.add(t, truth);
    if (t < 8 || t > 10) data.measured.add(t, truth + Eigen::Vector3d(0.004, -0.003, 0));
    data.predicted.add(t + 1, truth + Eigen::Vector3d(-0.01, 0.01, 0));
    data.arm_actual.add(t, truth + Eigen::Vector3d(0, 0, 0.05 + 0.01 * std::sin(t)));
    if (i % 10 == 0) data.arm_target.add(t, truth + Eigen::Vector3d(0, 0, 0.05));
  }
  data.occlusions.push_back({8.0, 10.0});
  Histogram vision{0.1, 1000, std::vector<int64_t>(40, 0)};
  for (int b = 10; b < 20; ++b) vision.counts[b] = 5 * (b - 9);
  data.latency_ms["vision"] = vision;
  data.latency_ms["predictor"] = Histogram{0, 50, {3, 9, 27, 9, 3}};
  data.latency_ms["arm"] = Histogram{0, 1, {}};
  data.events = {{5.0, "q1 approaching"}, {12.0, "q2 grasping"}, {14.5, "grasp: success"}};
  return data;
}

// A synthetic session gives four PNGs full of drawing, with the occlusion band on y_time.png.
TEST(SessionPlots, WritesFourFigures) {
  const TempDir temp;
  const std::string dir = temp.path + "/figures";
  const std::vector<std::string> paths = write_session_plots(synthetic_session(), dir);
  ASSERT_EQ(paths.size(), 4u);
  const char* names[] = {"xy.png", "y_time.png", "latency.png", "arm.png"};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(std::filesystem::path(paths[i]).filename(), names[i]);
    const cv::Mat image = cv::imread(paths[i]);
    ASSERT_FALSE(image.empty()) << paths[i];
    EXPECT_GT(count_non_background(image), 8000) << paths[i];
  }
  const cv::Mat xy = cv::imread(paths[0]);
  EXPECT_EQ(xy.cols, xy.rows);  // a square figure for the equal-aspect plane
  EXPECT_GT(count_colour(cv::imread(paths[1]), palette::kShade), 5000);
  EXPECT_EQ(count_colour(xy, palette::kShade), 0);
  EXPECT_GT(cv::imread(paths[2]).rows, 3 * 200);  // a panel per stage
  EXPECT_GT(cv::imread(paths[3]).rows, 3 * 200);  // x, y and z panels
}

// An empty PlotData still writes all four figures, each with a "no data" note.
TEST(SessionPlots, EmptyDataWritesNoDataFigures) {
  const TempDir temp;
  const std::string& dir = temp.path;
  const PlotData empty;  // (not PlotData{}: DecimatedSeries' constructor is explicit)
  const std::vector<std::string> paths = write_session_plots(empty, dir);
  ASSERT_EQ(paths.size(), 4u);
  // The note, in its own grey, sits at the centre of the axes (of the middle panel for arm.png).
  for (const std::string& path : paths) {
    const cv::Mat image = cv::imread(path);
    ASSERT_FALSE(image.empty()) << path;
    EXPECT_GT(count_non_background(image), 500) << path;
    const cv::Rect centre(image.cols / 2 - 100, image.rows / 2 - 40, 200, 80);
    EXPECT_GT(count_colour(image(centre), palette::kNote), 50) << path;
  }
  // With data there is no note (but latency.png's "arm" stage has no counts, so it has one).
  const std::vector<std::string> full =
      write_session_plots(synthetic_session(), temp.path + "/full");
  ASSERT_EQ(full.size(), 4u);
  EXPECT_EQ(count_colour(cv::imread(full[0]), palette::kNote), 0);
  EXPECT_EQ(count_colour(cv::imread(full[1]), palette::kNote), 0);
  EXPECT_GT(count_colour(cv::imread(full[2]), palette::kNote), 50);
  EXPECT_EQ(count_colour(cv::imread(full[3]), palette::kNote), 0);
}

}  // namespace
}  // namespace sg::logger
