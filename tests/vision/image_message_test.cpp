// image_t <-> frame: raw and JPEG round trips, and the refusals that keep a small message from
// making the decoder allocate a large image (a JPEG whose header declares 60000 x 60000).

#include "vision/image_message.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace sg::vision {
namespace {

using stereograsp::image_t;

cv::Mat test_frame() {
  cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(20, 40, 200));
  cv::circle(bgr, {32, 24}, 10, cv::Scalar(0, 0, 255), -1);
  return bgr;
}

/// The offset of the height field of the JPEG's first baseline frame header (SOF0, FF C0).
size_t sof0_height_offset(const std::vector<uint8_t>& jpeg) {
  for (size_t i = 2; i + 9 < jpeg.size(); ++i)
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xC0) return i + 5;  // marker, length(2), precision
  return 0;
}

// A raw frame and a JPEG frame come back with their size; the JPEG's header declares 64 x 48.
TEST(ImageMessage, RawAndJpegRoundTrip) {
  std::string error;
  const auto raw = decode_image(encode_image(test_frame(), image_t::LEFT, 1, 10, false), &error);
  ASSERT_TRUE(raw) << error;
  EXPECT_EQ(cv::norm(*raw, test_frame(), cv::NORM_INF), 0.0);
  const image_t jpeg = encode_image(test_frame(), image_t::LEFT, 1, 10, true, 95);
  EXPECT_EQ(jpeg_declared_size(jpeg.data), (std::pair{64, 48}));
  const auto decoded = decode_image(jpeg, &error);
  ASSERT_TRUE(decoded) << error;
  EXPECT_EQ(decoded->size(), cv::Size(64, 48));
}

// A JPEG whose header declares 60000 x 60000 inside a message that says 64 x 48 is refused from
// its header (decoding it would allocate 10 GB).
TEST(ImageMessage, JpegDeclaringAnotherSizeIsRefusedBeforeDecoding) {
  image_t m = encode_image(test_frame(), image_t::LEFT, 1, 10, true);
  const size_t at = sof0_height_offset(m.data);
  ASSERT_GT(at, 0u);
  for (size_t k : {at, at + 2}) {  // height, then width: 60000 = 0xEA60
    m.data[k] = 0xEA;
    m.data[k + 1] = 0x60;
  }
  EXPECT_EQ(jpeg_declared_size(m.data), (std::pair{60000, 60000}));
  std::string error;
  EXPECT_FALSE(decode_image(m, &error));
  EXPECT_EQ(error, "JPEG header declares 60000x60000, the message 64x48");
}

// A message that itself claims more than 4096 x 4096 pixels, or a non-positive size, is refused.
TEST(ImageMessage, OversizedClaimsAreRefused) {
  image_t m = encode_image(test_frame(), image_t::LEFT, 1, 10, true);
  std::string error;
  for (const auto& [w, h] : {std::pair{60000, 60000}, {4097, 4096}, {0, 48}, {64, -1}}) {
    m.width = w;
    m.height = h;
    EXPECT_FALSE(decode_image(m, &error)) << w << "x" << h;
    EXPECT_NE(error.find("is not valid"), std::string::npos) << error;
  }
}

// Bytes that are not a JPEG are refused by the header check, with their reason.
TEST(ImageMessage, GarbageJpegIsRefused) {
  image_t m = encode_image(test_frame(), image_t::LEFT, 1, 10, true);
  m.data.assign(200, 0x5A);
  m.size = 200;
  std::string error;
  EXPECT_FALSE(jpeg_declared_size(m.data));
  EXPECT_FALSE(decode_image(m, &error));
  EXPECT_EQ(error, "JPEG header does not decode");
}

}  // namespace
}  // namespace sg::vision
