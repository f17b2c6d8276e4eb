#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "common/message_types.hpp"
#include "vision/blob_tracker.hpp"

namespace sg::vision {

/// An image_t from a BGR frame: JPEG (quality 1-100, 4:2:0, restart markers every 4 MCUs of each
/// row, so that sg-vision can decode a window's segments alone: jpeg_band.hpp) or raw BGR8.
stereograsp::image_t encode_image(const cv::Mat& bgr, int8_t camera, int64_t frame_number,
                                  int64_t utime, bool jpeg, int jpeg_quality = 90);

/// Most pixels a frame may have: 4096 x 4096 (50 MB as BGR). Larger claims are refused before
/// anything is allocated for them.
constexpr int64_t kMaxImagePixels = int64_t{4096} * 4096;

/// What is wrong with an image_t before it is decoded ("" when nothing): a size of no pixels or
/// more than kMaxImagePixels, a `size` other than the data's, a JPEG whose header does not read or
/// declares another size, an unknown format, raw rows that need more bytes than it holds. Cheap
/// (a JPEG's header only), so a bad image is refused as it arrives.
std::string image_message_error(const stereograsp::image_t& message);

/// The BGR frame in an image_t, or nullopt with `error` saying what is wrong (a size that does
/// not match the data, an unknown format, more than kMaxImagePixels, a JPEG whose header
/// declares another size than the message, a JPEG that does not decode). A JPEG's size is read
/// from its header first (libjpeg-turbo), so a small message cannot make the decoder allocate a
/// large image (a decompression bomb).
std::optional<cv::Mat> decode_image(const stereograsp::image_t& message, std::string* error);

/// Width and height a JPEG declares in its header, without decoding it; nullopt when the bytes
/// are not a JPEG header libjpeg-turbo can read.
std::optional<std::pair<int, int>> jpeg_declared_size(const std::vector<uint8_t>& jpeg);

/// A blob_t for one camera's observation of one frame.
stereograsp::blob_t to_blob_t(const Observation& o, int8_t camera, int64_t frame_number,
                              int64_t utime);

}  // namespace sg::vision
