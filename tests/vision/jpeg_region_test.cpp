// JpegRegionDecoder: a region decodes bit for bit as the whole image does, on real photographs
// (opencv-doc: 4:2:2, 4:2:0 at an odd size) and on frames OpenCV encodes (4:2:0, progressive,
// greyscale); the whole decode is OpenCV's; only the region's iMCUs are written; and what is not
// the declared JPEG is refused in one line.

#include "vision/jpeg_region.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "sim/real_scene.hpp"

namespace sg::vision {
namespace {

std::vector<uint8_t> read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

struct Jpeg {
  std::string name;
  std::vector<uint8_t> bytes;
  cv::Size size;
};

/// A frame like the simulator's: a red ball on a textured background.
cv::Mat synthetic_frame() {
  cv::Mat bgr(480, 640, CV_8UC3);
  cv::randu(bgr, 0, 255);
  cv::GaussianBlur(bgr, bgr, {7, 7}, 2);
  cv::circle(bgr, {317, 203}, 21, cv::Scalar(20, 30, 210), -1, cv::LINE_AA);
  return bgr;
}

std::vector<uint8_t> encode(const cv::Mat& image, std::vector<int> params) {
  std::vector<uint8_t> out;
  cv::imencode(".jpg", image, out, params);
  return out;
}

/// Real photographs and encoded frames, with the subsampling and modes a camera may send.
const std::vector<Jpeg>& jpegs() {
  static const std::vector<Jpeg> all = [] {
    const std::string data = sim::opencv_data_dir() + "/";
    const cv::Mat frame = synthetic_frame();
    cv::Mat grey;
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    std::vector<Jpeg> v = {
        {"fruits.jpg (4:2:2)", read_file(data + "fruits.jpg"), {}},
        {"aloeL.jpg (4:2:0, 1282x1110)", read_file(data + "aloeL.jpg"), {}},
        {"frame (4:2:0, q 90)", encode(frame, {cv::IMWRITE_JPEG_QUALITY, 90}), {}},
        {"frame (progressive)", encode(frame, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}), {}},
        {"frame (greyscale)", encode(grey, {}), {}},
        // restart markers: every MCU row, every second row, in rows of 8 px (greyscale), ten a
        // row, and every 3 MCUs (not at row boundaries: rows are skipped instead of cut)
        {"frame (RST every row)", encode(frame, {cv::IMWRITE_JPEG_RST_INTERVAL, 40}), {}},
        {"frame (RST every 2 rows)", encode(frame, {cv::IMWRITE_JPEG_RST_INTERVAL, 80}), {}},
        {"frame (greyscale, RST every row)", encode(grey, {cv::IMWRITE_JPEG_RST_INTERVAL, 80}), {}},
        {"frame (RST every 4 MCUs)", encode(frame, {cv::IMWRITE_JPEG_RST_INTERVAL, 4}), {}},
        {"frame (RST every 3 MCUs)", encode(frame, {cv::IMWRITE_JPEG_RST_INTERVAL, 3}), {}},
    };
    for (Jpeg& j : v) {
      const cv::Mat m = cv::imdecode(j.bytes, cv::IMREAD_UNCHANGED);
      j.size = m.size();
    }
    return v;
  }();
  return all;
}

/// The whole image decoded by the decoder under test.
cv::Mat whole(const Jpeg& j) {
  JpegRegionDecoder decoder;
  cv::Mat bgr;
  const auto r = decoder.decode(j.bytes.data(), j.bytes.size(), j.size, {}, bgr);
  EXPECT_TRUE(r.ok) << j.name << ": " << r.error;
  EXPECT_EQ(r.decoded, cv::Rect({}, j.size)) << j.name;
  return bgr;
}

/// Regions at the corners and edges, of odd sizes and offsets, and at random.
std::vector<cv::Rect> regions(cv::Size s) {
  std::vector<cv::Rect> v = {{0, 0, 17, 9},
                             {s.width - 31, s.height - 29, 31, 29},
                             {s.width - 5, 0, 5, s.height},
                             {0, s.height / 2, s.width, 3},
                             {s.width / 2 - 40, s.height / 2 - 40, 80, 80},
                             {-20, -20, 50, 50},
                             {s.width - 10, s.height - 10, 60, 60}};
  std::mt19937 rng(1);
  for (int k = 0; k < 40; ++k) {
    const int w = 1 + static_cast<int>(rng() % 160), h = 1 + static_cast<int>(rng() % 160);
    v.push_back({static_cast<int>(rng() % static_cast<unsigned>(s.width)),
                 static_cast<int>(rng() % static_cast<unsigned>(s.height)), w, h});
  }
  return v;
}

// Every region's pixels are the whole decode's, bit for bit, and the decoded rect covers it.
TEST(JpegRegionDecoder, RegionIsBitIdenticalToTheWholeDecode) {
  for (const Jpeg& j : jpegs()) {
    SCOPED_TRACE(j.name);
    ASSERT_FALSE(j.bytes.empty());
    const cv::Mat all = whole(j);
    JpegRegionDecoder decoder;  // one decoder for every region, as sg-vision keeps one
    cv::Mat bgr(j.size, CV_8UC3, cv::Scalar(77, 77, 77));
    for (const cv::Rect& asked : regions(j.size)) {
      SCOPED_TRACE(testing::Message() << asked);
      const auto r = decoder.decode(j.bytes.data(), j.bytes.size(), j.size, asked, bgr);
      ASSERT_TRUE(r.ok) << r.error;
      const cv::Rect region = asked & cv::Rect({}, j.size);
      EXPECT_EQ(r.decoded & region, region);
      EXPECT_EQ(cv::norm(bgr(region), all(region), cv::NORM_INF), 0.0);
    }
  }
}

// A JPEG with restart markers at MCU-row boundaries is cut (jpeg_band.hpp) for every region short
// of the whole image; any other is decoded by skipping rows.
TEST(JpegRegionDecoder, PartsAreCutWhereRestartsAreAtRowBoundaries) {
  for (const Jpeg& j : jpegs()) {
    SCOPED_TRACE(j.name);
    JpegRegionDecoder decoder;
    cv::Mat bgr;
    for (const cv::Rect& asked : regions(j.size)) {
      ASSERT_TRUE(decoder.decode(j.bytes.data(), j.bytes.size(), j.size, asked, bgr).ok);
    }
    const bool row_restarts =
        j.name.find("RST every") != std::string::npos && j.name.find("3 MCUs") == std::string::npos;
    if (row_restarts)
      EXPECT_GE(decoder.parts(), regions(j.size).size() - 3);  // all but the full-height ones
    else
      EXPECT_EQ(decoder.parts(), 0u);
  }
}

// A JPEG whose restart markers do not count RST0, RST1, ... (a corrupt or crafted one) is not cut
// but decoded by libjpeg-turbo as it is, which warns of the markers and goes on.
TEST(JpegRegionDecoder, MisnumberedRestartsAreNotCut) {
  std::vector<uint8_t> bytes = jpegs()[5].bytes;  // RST every row
  size_t changed = 0;
  for (size_t i = 0; i + 1 < bytes.size() && changed == 0; ++i)
    if (bytes[i] == 0xFF && bytes[i + 1] == 0xD3) bytes[i + 1] = 0xD5, ++changed;
  ASSERT_EQ(changed, 1u);
  JpegRegionDecoder decoder;
  cv::Mat bgr;
  const auto r = decoder.decode(bytes.data(), bytes.size(), {640, 480}, {300, 200, 40, 40}, bgr);
  EXPECT_TRUE(r.ok) << r.error;
  EXPECT_EQ(decoder.parts(), 0u);
  EXPECT_GT(decoder.warnings(), 0u);
}

// The whole decode is OpenCV's imdecode, pixel for pixel (a greyscale JPEG as BGR).
TEST(JpegRegionDecoder, WholeDecodeIsOpenCvs) {
  for (const Jpeg& j : jpegs()) {
    SCOPED_TRACE(j.name);
    const cv::Mat theirs = cv::imdecode(j.bytes, cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION);
    EXPECT_EQ(cv::norm(whole(j), theirs, cv::NORM_INF), 0.0);
  }
}

// A search window of a 640x480 frame decodes the window and 4 px more on each side (the reach of
// the upsampling of its edge), from the top of its first iMCU row and the left of its first iMCU
// column; the pixels outside keep what they held.
TEST(JpegRegionDecoder, OnlyTheRegionsIMCUsAreWritten) {
  const Jpeg& j = jpegs()[2];  // 4:2:0: iMCUs of 16 x 16
  JpegRegionDecoder decoder;
  cv::Mat bgr(j.size, CV_8UC3, cv::Scalar(77, 77, 77));
  const cv::Rect window(277, 163, 80, 80);
  const auto r = decoder.decode(j.bytes.data(), j.bytes.size(), j.size, window, bgr);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.decoded.x % 16, 0);
  EXPECT_EQ(r.decoded.x, 272);  // 277 - 4, down to the iMCU column at 16 x 17
  EXPECT_EQ(r.decoded.br().x, 277 + 80 + 4);
  EXPECT_EQ(r.decoded.y, 144);  // 163 - 4, up to the iMCU row at 16 x 9
  EXPECT_EQ(r.decoded.br().y, 163 + 80 + 4);
  cv::Mat outside = bgr.clone();
  outside(r.decoded).setTo(cv::Scalar(77, 77, 77));
  EXPECT_EQ(cv::countNonZero(outside.reshape(1) != 77), 0);
}

// A size other than the message's, bytes that are not a JPEG, a truncated JPEG and an empty one:
// each refused with its reason, or (truncated) decoded through with a warning counted.
TEST(JpegRegionDecoder, RefusesWhatIsNotTheDeclaredJpeg) {
  const Jpeg& j = jpegs()[2];
  JpegRegionDecoder decoder;
  cv::Mat bgr;
  auto r = decoder.decode(j.bytes.data(), j.bytes.size(), {320, 240}, {}, bgr);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "JPEG header declares 640x480, the message 320x240");
  const std::vector<uint8_t> garbage(1000, 0x5A);
  r = decoder.decode(garbage.data(), garbage.size(), j.size, {}, bgr);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error.rfind("JPEG does not decode: ", 0), 0u) << r.error;
  r = decoder.decode(j.bytes.data(), 0, j.size, {}, bgr);
  EXPECT_EQ(r.error, "empty JPEG");
  r = decoder.decode(j.bytes.data(), j.bytes.size() / 2, j.size, {}, bgr);
  EXPECT_TRUE(r.ok) << r.error;  // libjpeg-turbo fills the missing rows, and warns
  EXPECT_GT(decoder.warnings(), 0u);
  r = decoder.decode(j.bytes.data(), j.bytes.size(), j.size, {}, bgr);  // and recovers
  EXPECT_TRUE(r.ok) << r.error;
  EXPECT_EQ(cv::norm(bgr, whole(j), cv::NORM_INF), 0.0);
}

// A progressive JPEG of 100 scans (tests/fixtures/jpeg, made by jpegtran) is valid, and OpenCV
// decodes it; the region decoder refuses it for its scans.
TEST(JpegRegionDecoder, ProgressiveWithTooManyScansIsRefused) {
  const std::vector<uint8_t> bytes =
      read_file(std::string(SG_SOURCE_DIR) + "/tests/fixtures/jpeg/many_scans.jpg");
  ASSERT_EQ(bytes.size(), 5314u);
  EXPECT_EQ(cv::imdecode(bytes, cv::IMREAD_COLOR).size(), cv::Size(96, 72));
  JpegRegionDecoder decoder;
  cv::Mat bgr;
  const auto r = decoder.decode(bytes.data(), bytes.size(), {96, 72}, {}, bgr);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "JPEG does not decode: progressive JPEG with more than 50 scans");
}

// A frame the decoder allocates has no row, nor any iMCU column's start in a row, on a 16-byte
// boundary, where libjpeg-turbo's SIMD colour conversion would write it past the cache.
TEST(JpegRegionDecoder, AllocatedRowsAreNeverOnA16ByteBoundary) {
  const Jpeg& j = jpegs()[2];
  JpegRegionDecoder decoder;
  cv::Mat bgr;
  ASSERT_TRUE(decoder.decode(j.bytes.data(), j.bytes.size(), j.size, {300, 200, 40, 40}, bgr).ok);
  ASSERT_EQ(bgr.size(), j.size);
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; x += 8)
      ASSERT_NE(reinterpret_cast<uintptr_t>(bgr.ptr<uint8_t>(y, x)) % 16, 0u) << x << ", " << y;
}

}  // namespace
}  // namespace sg::vision
