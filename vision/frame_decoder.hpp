#pragma once

/// One camera's image_t messages into frames for its tracker, decoding a JPEG only where the
/// tracker will look (issue 19). sg-vision keeps one per camera and asks each BlobTracker which
/// pixels its next detect() reads (BlobTracker::next_window, StereoStep::next_windows):
///
///     FrameDecoder decoder(FrameDecoder::Mode::kRegion);
///     std::string error;
///     const cv::Mat* frame = decoder.decode(message, step.next_windows()[0], &error);
///     if (!frame) spdlog::warn("dropped: {}", error);
///
/// A JPEG is decoded into a frame kept from one message to the next (JpegRegionDecoder): its
/// pixels outside the region are those of earlier frames, which the tracker does not read. Raw
/// images (BGR8, RGB8, GRAY8) are converted whole, as decode_image() does. kFull decodes every
/// JPEG whole: the baseline the benchmarks compare against, and a switch (vision.decode) for a
/// tracker change that might read outside its window.
///
/// The message's own checks come first (size against data, at most kMaxImagePixels, a JPEG
/// header declaring the message's size), so a small message cannot make it allocate a large
/// frame.

#include <opencv2/core.hpp>
#include <string>

#include "stereograsp/image_t.hpp"
#include "vision/jpeg_region.hpp"

namespace sg::vision {

class FrameDecoder {
 public:
  enum class Mode {
    kRegion,  ///< a JPEG's region only
    kFull,    ///< every JPEG whole
  };

  explicit FrameDecoder(Mode mode = Mode::kRegion) : mode_(mode) {}

  /// The BGR frame of `message` with at least `region` decoded (an empty region: all of it), or
  /// nullptr with `error` saying why. The frame stays valid until the next decode().
  const cv::Mat* decode(const stereograsp::image_t& message, cv::Rect region, std::string* error);

  Mode mode() const { return mode_; }
  /// The pixels decoded by the last decode() of a JPEG.
  const cv::Rect& decoded() const { return decoded_; }
  /// libjpeg-turbo's warnings so far (corrupt JPEGs it decoded through).
  uint64_t jpeg_warnings() const { return jpeg_.warnings(); }

 private:
  Mode mode_;
  JpegRegionDecoder jpeg_;
  cv::Mat frame_;
  cv::Rect decoded_;
};

}  // namespace sg::vision
