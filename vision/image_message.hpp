#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "common/message_types.hpp"
#include "vision/blob_tracker.hpp"

namespace sg::vision {

/// An image_t from a BGR frame: JPEG (quality 1-100) or raw BGR8.
stereograsp::image_t encode_image(const cv::Mat& bgr, int8_t camera, int64_t frame_number,
                                  int64_t utime, bool jpeg, int jpeg_quality = 90);

/// The BGR frame in an image_t, or nullopt with `error` saying what is wrong (a size that does
/// not match the data, an unknown format, a JPEG that does not decode).
std::optional<cv::Mat> decode_image(const stereograsp::image_t& message, std::string* error);

/// A blob_t for one camera's observation of one frame.
stereograsp::blob_t to_blob_t(const Observation& o, int8_t camera, int64_t frame_number,
                              int64_t utime);

}  // namespace sg::vision
