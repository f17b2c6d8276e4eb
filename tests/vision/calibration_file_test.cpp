// Calibration files: exact round trip, errors that name the key, no partial file over a good one.

#include "vision/calibration_file.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <memory>
#include <sstream>
#include <thread>

#include "tests/support/subprocess.hpp"

namespace sg::vision {
namespace {

StereoCalibration sample() {
  StereoCalibration c;
  c.left =
      CameraModel::look_at(640, 480, {530.5, 529.25, 321.0, 238.5},
                           {-0.2, 0.05, 0.001, -0.002, 0.01}, {0.8, -0.25, 0.4}, {0.45, 0, 0.1});
  c.right = CameraModel::look_at(640, 480, {531.0, 530.0, 318.0, 241.0}, {}, {0.8, 0.25, 0.4},
                                 {0.45, 0, 0.1});
  c.rms_left = 0.21;
  c.rms_right = 0.18;
  c.source = "test";
  return c;
}

// What is written is read back: every parameter to 1e-12.
TEST(CalibrationFile, RoundTrip) {
  const std::string path = test::make_temp_dir() + "/stereo.yaml";
  write_calibration(path, sample());
  const StereoCalibration back = read_calibration(path);
  for (const auto& [a, b] : {std::pair{sample().left, back.left}, {sample().right, back.right}}) {
    EXPECT_TRUE(a.K().isApprox(b.K(), 1e-12));
    EXPECT_TRUE(a.R().isApprox(b.R(), 1e-12));
    EXPECT_TRUE(a.t().isApprox(b.t(), 1e-12));
    EXPECT_NEAR(a.distortion().k1, b.distortion().k1, 1e-15);
    EXPECT_NEAR(a.distortion().p2, b.distortion().p2, 1e-15);
    EXPECT_EQ(b.width(), 640);
  }
  EXPECT_DOUBLE_EQ(back.rms_left, 0.21);
  EXPECT_EQ(back.source, "test");
  EXPECT_FALSE(back.date.empty());
  EXPECT_NE(test::read_text(path).find("P: !!opencv-matrix"), std::string::npos)
      << "P is written too";
}

// A missing or malformed key is named.
TEST(CalibrationFile, BadKeysAreNamed) {
  const std::string dir = test::make_temp_dir();
  write_calibration(dir + "/good.yaml", sample());
  const std::string good = test::read_text(dir + "/good.yaml");

  std::string no_k = good;
  const size_t right = no_k.find("camera_right");
  no_k.replace(no_k.find("   K:", right), 5, "   Q:");
  std::ofstream(dir + "/no_k.yaml") << no_k;
  try {
    read_calibration(dir + "/no_k.yaml");
    FAIL() << "accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("'camera_right.K' is missing"), std::string::npos)
        << e.what();
  }

  std::string bad_version = good;
  bad_version.replace(bad_version.find("format_version: 1"), 17, "format_version: 7");
  std::ofstream(dir + "/v7.yaml") << bad_version;
  EXPECT_THROW(read_calibration(dir + "/v7.yaml"), CalibrationError);

  std::ofstream(dir + "/garbage.yaml") << "%YAML:1.0\n---\nthis: [is, not\n";
  EXPECT_THROW(read_calibration(dir + "/garbage.yaml"), CalibrationError);
  EXPECT_THROW(read_calibration(dir + "/absent.yaml"), CalibrationError);
  // Not YAML: refused before OpenCV's XML parser, which crashed on this (fuzz/calibration_fuzz).
  std::ofstream(dir + "/crash.xml", std::ios::binary)
      << std::string("<?xmlSSfffffzfffff\nfffffffff=\0\0\0\0\0\0\0fxmlSSS", 43);
  EXPECT_THROW(read_calibration(dir + "/crash.xml"), CalibrationError);
  // A matrix claiming 10^5 x 10^5 is refused before OpenCV allocates it (fuzz/calibration_fuzz).
  std::string huge = good;
  huge.replace(huge.find("cols: 3", huge.find("camera_right")), 7, "cols: 100000");
  huge.replace(huge.rfind("rows: 3", huge.find("cols: 100000")), 7, "rows: 100000");
  std::ofstream(dir + "/huge.yaml") << huge;
  try {
    read_calibration(dir + "/huge.yaml");
    FAIL() << "accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("'camera_right.K' must be a 3x3 matrix"),
              std::string::npos)
        << e.what();
  }
}

// source and date are one line of text: a date holding NUL bytes, which FileStorage wrote back
// cut at the first (fuzz/calibration_fuzz), is refused naming the key; the writer refuses what
// the reader would; 1024 bytes round trip and 1025 do not.
TEST(CalibrationFile, SourceAndDateAreOneLineOfText) {
  const std::string dir = test::make_temp_dir();
  write_calibration(dir + "/good.yaml", sample());
  std::string nul = test::read_text(dir + "/good.yaml");
  const size_t date = nul.find("date: \"");
  ASSERT_NE(date, std::string::npos);
  nul.insert(date + 10, std::string("?\0\0\0", 4));
  std::ofstream(dir + "/nul.yaml", std::ios::binary) << nul;
  try {
    read_calibration(dir + "/nul.yaml");
    FAIL() << "accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find(":4: key 'date' must be one line of text"),
              std::string::npos)
        << e.what();
  }
  for (const std::string& bad : {std::string("two\nlines"), std::string("tab\there"),
                                 std::string("del\x7f"), std::string(1025, 'a')}) {
    for (std::string StereoCalibration::*text :
         {&StereoCalibration::source, &StereoCalibration::date}) {
      StereoCalibration c = sample();
      c.*text = bad;
      EXPECT_THROW(write_calibration(dir + "/bad.yaml", c), CalibrationError) << bad.size();
    }
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/bad.yaml"));
  StereoCalibration longest = sample();
  longest.source = std::string(1024, 'a');
  longest.date = "2026-12-07T18:00:00Z";
  write_calibration(dir + "/longest.yaml", longest);
  const StereoCalibration back = read_calibration(dir + "/longest.yaml");
  EXPECT_EQ(back.source, longest.source);
  EXPECT_EQ(back.date, longest.date);
}

// A failed write leaves the good file that was there.
TEST(CalibrationFile, FailedWriteKeepsTheOldFile) {
  const std::string dir = test::make_temp_dir();
  const std::string path = dir + "/stereo.yaml";
  write_calibration(path, sample());
  const std::string before = test::read_text(path);
  std::filesystem::create_directory(path + ".tmp");  // the temporary cannot be created
  StereoCalibration swapped = sample();
  std::swap(swapped.left, swapped.right);
  EXPECT_THROW(write_calibration(path, swapped), CalibrationError);
  EXPECT_EQ(test::read_text(path), before);
}

// A truncated file that made OpenCV's FileStorage loop for ever (fuzz/calibration_fuzz) is
// refused, naming the file, within a deadline.
TEST(CalibrationFile, TruncatedYamlThatHungOpenCvIsRefused) {
  const std::string path = test::make_temp_dir() + "/hang.yaml";
  std::ofstream(path, std::ios::binary) << "%YAML:1.0\n---%YAML:1.0\n\nf---\nformat_verso";
  auto outcome = std::make_shared<std::promise<std::string>>();
  std::thread([outcome, path] {  // detached: a hang must fail the test, not block it
    try {
      read_calibration(path);
      outcome->set_value("accepted");
    } catch (const CalibrationError& e) {
      outcome->set_value(e.what());
    }
  })
      .detach();
  std::future<std::string> error = outcome->get_future();
  ASSERT_EQ(error.wait_for(std::chrono::seconds(10)), std::future_status::ready)
      << "read_calibration hangs";
  const std::string what = error.get();
  EXPECT_TRUE(what.starts_with(path + ":")) << what;
}

}  // namespace
}  // namespace sg::vision
