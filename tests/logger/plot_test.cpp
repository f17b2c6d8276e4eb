// The gnuplot layer (logger/plot.hpp) and the session figures (logger/session_plots.hpp): data
// files and scripts for known input, PNGs read back (size, not blank, the series' colours where
// expected), gnuplot's errors reported in one line, and a missing gnuplot skipping the plots
// while the report is still written.

#include "logger/plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "common/message_types.hpp"
#include "logger/report.hpp"
#include "logger/session_plots.hpp"
#include "tests/support/subprocess.hpp"

namespace sg::logger {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A new temporary directory, removed with its contents at the end of the test (kept, to look at
// the figures, when the environment sets SG_KEEP_TEST_FILES).
struct TempDir {
  TempDir() : path(test::make_temp_dir()) {}
  ~TempDir() {
    if (std::getenv("SG_KEEP_TEST_FILES") != nullptr) return;
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  std::string path;
};

// Sum of absolute channel differences between a pixel (OpenCV's BGR) and a colour.
int distance(const cv::Vec3b& pixel, const Rgb& rgb) {
  return std::abs(pixel[2] - rgb.r) + std::abs(pixel[1] - rgb.g) + std::abs(pixel[0] - rgb.b);
}

// Pixels of `image` within `tolerance` of `rgb` (0: exactly it).
int count_colour(const cv::Mat& image, const Rgb& rgb, int tolerance = 0) {
  int n = 0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) n += distance(image.at<cv::Vec3b>(y, x), rgb) <= tolerance;
  }
  return n;
}

int count_non_background(const cv::Mat& image) {
  return image.rows * image.cols - count_colour(image, palette::kBackground);
}

// Rows of a single-column-pair series.
std::vector<std::vector<double>> pairs(const std::vector<std::pair<double, double>>& points) {
  std::vector<std::vector<double>> rows;
  for (const auto& [a, b] : points) rows.push_back({a, b});
  return rows;
}

// Blocks are separated by two blank lines, a non-finite row becomes one blank line (a break),
// an all-non-finite block is not written.
TEST(GnuplotData, BlocksBreaksAndEmptyBlocks) {
  GnuplotData data;
  EXPECT_EQ(data.add_block("first", pairs({{0, 1}, {kNaN, 0}, {kInf, 1}, {2, 3.5}, {4, kNaN}})), 0);
  EXPECT_EQ(data.add_block("nothing finite", pairs({{kNaN, 1}, {2, kInf}})), -1);
  EXPECT_EQ(data.add_block("none", {}), -1);
  EXPECT_EQ(data.add_block("second\nline", pairs({{-0.25, 1e-7}, {1234567.125, 1.0 / 3}})), 1);
  EXPECT_EQ(data.text(),
            "# first\n0 1\n\n2 3.5\n\n\n\n"
            "# second?line\n-0.25 1e-07\n1234567.125 0.3333333333\n");
  EXPECT_EQ(data.blocks(), 2);
  EXPECT_EQ(data.rows(0), 2);
  EXPECT_EQ(data.rows(1), 2);
  EXPECT_EQ(data.rows(-1), 0);
}

// Text can only ever be a string in a script: quotes doubled, control bytes and non-ASCII
// replaced, long text shortened.
TEST(GnuplotText, StringsAndNumbers) {
  EXPECT_EQ(gnuplot_string("q4 object lifted (success)"), "'q4 object lifted (success)'");
  EXPECT_EQ(gnuplot_string("it's"), "'it''s'");
  EXPECT_EQ(gnuplot_string("a\nb\x01\xc2\xb5"), std::string("'a?b") + std::string(3, '?') + "'");
  EXPECT_EQ(gnuplot_string("abcdefghij", 8), "'abcde...'");
  EXPECT_EQ(gnuplot_number(0.1), "0.1");
  EXPECT_EQ(gnuplot_number(-1.0 / 3), "-0.3333333333");
  EXPECT_EQ(gnuplot_number(kNaN), "NaN");
  EXPECT_EQ(gnuplot_number(-kInf), "-1e308");
  EXPECT_EQ((Rgb{31, 119, 180}.hex()), "#1f77b4");
}

// A gnuplot that is not there is one line naming the Debian package.
TEST(Gnuplot, MissingProgramIsOneLine) {
  for (const std::string& program :
       {std::string("/nonexistent/gnuplot"), std::string("sg-no-such-gnuplot")}) {
    try {
      find_gnuplot(program);
      FAIL() << program;
    } catch (const GnuplotMissing& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(program), std::string::npos) << what;
      EXPECT_NE(what.find("gnuplot-nox"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  EXPECT_EQ(fs::path(find_gnuplot()).filename(), "gnuplot");  // installed by bootstrap.sh
}

// gnuplot draws a known script at the requested size; a label made by gnuplot_string from
// hostile text stays a label (no command runs); a broken script gives gnuplot's message.
TEST(Gnuplot, RunsScriptsAndReportsErrors) {
  const TempDir temp;
  const std::string gnuplot = find_gnuplot();
  write_text_file(temp.path + "/t.gp",
                  "set terminal pngcairo size 320,240\nset output 't.png'\n"
                  "set label " +
                      gnuplot_string("x'; system('touch pwned'); '") +
                      " at graph 0.1, graph 0.5\n"
                      "set xrange [0:1]\nset yrange [0:1]\n"
                      "set object rect from 0.2, 0.2 to 0.8, 0.8 fc rgb '#ffe4b5' fs solid 1.0 "
                      "noborder\nplot NaN notitle\n");
  run_gnuplot(gnuplot, temp.path, "t.gp");
  const cv::Mat image = cv::imread(temp.path + "/t.png");
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 320);
  EXPECT_EQ(image.rows, 240);
  EXPECT_GT(count_colour(image, palette::kShade), 5000);
  EXPECT_FALSE(fs::exists(temp.path + "/pwned"));

  write_text_file(temp.path + "/bad.gp", "set terminal pngcairo\nplot no_such_variable\n");
  try {
    run_gnuplot(gnuplot, temp.path, "bad.gp");
    FAIL() << "no exception";
  } catch (const PlotError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(temp.path + "/bad.gp"), std::string::npos) << what;
    EXPECT_NE(what.find("line 2"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// Names of close markers go to the next free row; one that would pass the right edge ends at
// its marker; with every row taken a marker gets no name.
TEST(SessionPlots, LabelRows) {
  // Axes 0..100 over 1000 px, 7 px a character: a 9-character name is 70 px (7 units) wide.
  const std::vector<size_t> nine(6, 9);
  EXPECT_EQ(label_rows({0, 10, 12, 14, 16, 30}, nine, 0, 100, 1000),
            (std::vector<int>{0, 0, 1, 2, -1, 0}));
  EXPECT_EQ(label_rows({95, 98}, {9, 9}, 0, 100, 1000), (std::vector<int>{0, 1}));
  EXPECT_EQ(label_rows({1, 2}, {3, 3}, 5, 5, 1000), (std::vector<int>{-1, -1}));
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

// The colours a figure must show, each in at least `min` pixels (antialiased: near the colour).
void expect_colours(const cv::Mat& image, const std::vector<Rgb>& colours, int min,
                    const std::string& name) {
  for (const Rgb& c : colours) EXPECT_GE(count_colour(image, c, 30), min) << name << c.hex();
}

// A synthetic session gives four PNGs of the set sizes showing every series' colour, the
// occlusion band on y_time.png only, and data files and scripts with the known contents.
TEST(SessionPlots, WritesFourFigures) {
  const TempDir temp;
  const std::string dir = temp.path + "/figures";
  const std::vector<std::string> paths = write_session_plots(synthetic_session(), dir);
  ASSERT_EQ(paths.size(), 4u);
  const char* names[] = {"xy", "y_time", "latency", "arm"};
  const int sizes[][2] = {{800, 800}, {1100, 500}, {900, 3 * 230}, {1100, 820}};
  std::vector<cv::Mat> images;
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(paths[i], dir + "/" + names[i] + ".png");
    EXPECT_TRUE(fs::exists(dir + "/" + names[i] + ".gp")) << names[i];
    EXPECT_TRUE(fs::exists(dir + "/" + names[i] + ".dat")) << names[i];
    images.push_back(cv::imread(paths[i]));
    ASSERT_FALSE(images[i].empty()) << paths[i];
    EXPECT_EQ(images[i].cols, sizes[i][0]) << names[i];
    EXPECT_EQ(images[i].rows, sizes[i][1]) << names[i];
    EXPECT_GT(count_non_background(images[i]), 8000) << names[i];
  }
  expect_colours(images[0], {palette::kGreen, palette::kBlue, palette::kOrange}, 200, "xy");
  expect_colours(images[1], {palette::kGreen, palette::kBlue, palette::kOrange, palette::kPurple},
                 100, "y_time");
  expect_colours(images[2], {palette::kBlue}, 2000, "latency");
  expect_colours(images[3], {palette::kBlue, palette::kOrange, palette::kPurple}, 100, "arm");
  EXPECT_GT(count_colour(images[1], palette::kShade), 20000);  // 2 s of 21.5, 370 px high
  EXPECT_EQ(count_colour(images[0], palette::kShade), 0);
  EXPECT_EQ(count_colour(images[1], palette::kNote, 30), 0);   // data: no "no data" note
  EXPECT_GT(count_colour(images[2], palette::kNote, 30), 50);  // but the "arm" stage has none

  // The numbers: truth at t = 0 is (0.65, 0), at 0.05 s (0.5 + 0.15 cos 0.03, 0.15 sin 0.03);
  // 400 truth rows, 160 + 199 measured (t < 8 s or t > 10 s), 400 predicted; no gaps.
  const std::string xy = test::read_text(dir + "/xy.dat");
  EXPECT_EQ(
      xy.rfind("# true (GROUND_TRUTH): X (m), Y (m)\n0.65 0\n0.6499325051 0.00449932503\n", 0), 0u)
      << xy.substr(0, 200);
  EXPECT_EQ(test::count_lines(xy), 3 + 400 + 359 + 400 + 2 * 2);
  const std::string y_time = test::read_text(dir + "/y_time.gp");
  for (const char* line :
       {"set output 'y_time.png'", "set xlabel 'time (s)'", "set ylabel 'Y (m)'",
        "set object rect from 8, graph 0 to 10, graph 1 behind fc rgb '#ffe4b5'",
        "set label 'q1 approaching' at 5, graph 1 left", "title 'predicted (h = 4)'",
        "'y_time.dat' index 2 using 1:2 with points pt 2"}) {
    EXPECT_NE(y_time.find(line), std::string::npos) << line << "\n" << y_time;
  }
  const std::string latency = test::read_text(dir + "/latency.gp");
  EXPECT_NE(latency.find("set title 'predictor: n = 51, median ~ 25 ms'"), std::string::npos);
  EXPECT_NE(latency.find("set title 'vision: n = 275, median ~"), std::string::npos);
  EXPECT_NE(test::read_text(dir + "/latency.dat").find("# predictor: bin from (ms)"),
            std::string::npos);
}

// Figure 5 leaves out the points while the arm holds the ball (ball_held: the calibration to
// 2.025 s, the carried ball from 15.025 s): truth at 2.05..15.0 s (260 points), measured there
// but in the occlusion (119 + 100), predicted with targets there (t + 1: 260); figure 6 keeps all.
TEST(SessionPlots, FigureFiveLeavesOutTheHeldBall) {
  const TempDir temp;
  PlotData data = synthetic_session();
  data.ball_held = {{0.0, 2.025}, {15.025, 21.0}};
  write_session_plots(data, temp.path);
  const std::string xy = test::read_text(temp.path + "/xy.dat");
  EXPECT_EQ(test::count_lines(xy), 3 + 260 + 219 + 260 + 2 * 2);
  EXPECT_EQ(xy.find("\n0.65 0\n"), std::string::npos);  // the truth at t = 0 is left out
  const std::string y_time = test::read_text(temp.path + "/y_time.dat");
  EXPECT_EQ(test::count_lines(y_time), 3 + 400 + 400 + 359 + 2 * 2);
  EXPECT_NE(test::read_text(temp.path + "/xy.gp")
                .find("# left out: the points while the arm "
                      "holds the ball (start, end in s): 0-2.025 "
                      "15.025-21\n"),
            std::string::npos);
}

// A script re-run by hand in its directory draws the same figure again.
TEST(SessionPlots, ScriptsRerunByHand) {
  const TempDir temp;
  write_session_plots(synthetic_session(), temp.path);
  const std::string first = test::read_text(temp.path + "/arm.png");
  fs::remove(temp.path + "/arm.png");
  run_gnuplot(find_gnuplot(), temp.path, "arm.gp");
  EXPECT_EQ(test::read_text(temp.path + "/arm.png"), first);
}

// An empty PlotData still writes all four figures, each with a "no data" note at its centre.
TEST(SessionPlots, EmptyDataWritesNoDataFigures) {
  const TempDir temp;
  const PlotData empty;  // (not PlotData{}: DecimatedSeries' constructor is explicit)
  const std::vector<std::string> paths = write_session_plots(empty, temp.path);
  ASSERT_EQ(paths.size(), 4u);
  for (const std::string& path : paths) {
    const cv::Mat image = cv::imread(path);
    ASSERT_FALSE(image.empty()) << path;
    EXPECT_GT(count_non_background(image), 500) << path;
    const cv::Rect centre(image.cols / 2 - 100, image.rows / 2 - 40, 200, 80);
    EXPECT_GT(count_colour(image(centre), palette::kNote, 30), 50) << path;
  }
}

// Without gnuplot the data files and scripts are still written, and the error says so.
TEST(SessionPlots, MissingGnuplotWritesScriptsAndThrows) {
  const TempDir temp;
  try {
    write_session_plots(synthetic_session(), temp.path, "/nonexistent/gnuplot");
    FAIL() << "no exception";
  } catch (const GnuplotMissing& e) {
    EXPECT_NE(std::string(e.what()).find("gnuplot-nox"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(temp.path + "/*.gp"), std::string::npos) << e.what();
  }
  for (const char* name : {"xy", "y_time", "latency", "arm"}) {
    EXPECT_TRUE(fs::exists(temp.path + "/" + name + ".gp")) << name;
    EXPECT_TRUE(fs::exists(temp.path + "/" + name + ".dat")) << name;
    EXPECT_FALSE(fs::exists(temp.path + "/" + name + ".png")) << name;
  }
}

// A report made where PATH holds no gnuplot: report.md, report.json and the CSV are written,
// and one note says the plots were skipped and why.
TEST(SessionPlots, ReportWithoutGnuplotSkipsPlotsOnly) {
  const TempDir temp;
  const std::string log_path = temp.path + "/session.lcmlog";
  {
    lcm::LogFile log(log_path, "w");
    for (int k = 0; k < 30; ++k) {
      stereograsp::point3_t p{};
      p.utime = 1'700'000'000'000'000 + k * 33'333;
      p.visible = true;
      p.position[0] = 0.5;
      std::vector<uint8_t> bytes = encode_message(p);
      lcm::LogEvent e{0, p.utime + 5000, "OBJECT_POSITION", static_cast<int32_t>(bytes.size()),
                      bytes.data()};
      log.writeEvent(&e);
    }
  }
  const std::string saved_path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", (temp.path + "/no-programs-here").c_str(), 1);
  ReportOptions options;
  options.out_dir = temp.path + "/report";
  ReportResult r;
  EXPECT_NO_THROW(r = make_report(log_path, options));
  setenv("PATH", saved_path.c_str(), 1);
  EXPECT_FALSE(r.plots_written);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_EQ(r.notes[0].rfind("plots skipped: gnuplot not found on PATH (Debian package "
                             "gnuplot-nox)",
                             0),
            0u)
      << r.notes[0];
  EXPECT_TRUE(fs::exists(options.out_dir + "/report.md"));
  EXPECT_TRUE(fs::exists(options.out_dir + "/report.json"));
  EXPECT_TRUE(fs::exists(options.out_dir + "/csv/OBJECT_POSITION.csv"));
  EXPECT_TRUE(fs::exists(options.out_dir + "/xy.gp"));
  EXPECT_FALSE(fs::exists(options.out_dir + "/xy.png"));
}

}  // namespace
}  // namespace sg::logger
