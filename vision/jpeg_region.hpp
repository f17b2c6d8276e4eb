#pragma once

/// Decoding only the part of a JPEG that the tracker reads (issue 19). In tracking mode sg-vision
/// looks at one search window per camera, about 2 % of a 640x480 frame (section 5.1); decoding
/// the rest only to ignore it was most of a frame's time. libjpeg-turbo decodes a band of rows
/// (`jpeg_skip_scanlines` to its first row, `jpeg_read_scanlines` through its last) and, within
/// it, only the iMCU columns that cover the window (`jpeg_crop_scanline`, which widens the
/// request to iMCU boundaries, 8 or 16 px). The DCT blocks above the band are still entropy-
/// decoded (a baseline JPEG has no index), but not transformed, upsampled or colour-converted —
/// unless the JPEG has restart markers at MCU-row boundaries: then only the restart segments
/// around the region are decoded at all (jpeg_band.hpp), as in sg-camera-sim's frames.
///
///     JpegRegionDecoder decoder;
///     cv::Mat frame;                                        // kept from frame to frame
///     const auto r = decoder.decode(jpeg.data(), jpeg.size(), {640, 480}, window, frame);
///     if (!r.ok) spdlog::warn("dropped: {}", r.error);
///     tracker.detect(frame);                                // reads only `window`
///
/// The pixels of `region` are bit for bit those of a whole decode by the same decoder (a test, and
/// the jpeg_region fuzzer): the request is widened by 4 px on every side (then to the iMCU row
/// above and the iMCU column to the left), so the upsampling's neighbours of the region's edge
/// pixels, one chroma sample away, are decoded too. Pixels outside the decoded rect keep what they
/// held.
///
/// A frame the decoder allocates has its rows off every 16-byte boundary: libjpeg-turbo's SIMD
/// colour conversion writes a row that starts on one with non-temporal stores, past the cache,
/// which made a window's decode up to 2x slower, and the tracking step after it 2x (vision_bench).
///
/// Hostile input: the JPEG's own header must declare the size the caller expects (checked before
/// anything is allocated); a progressive JPEG may have at most kMaxScans scans (a crafted one
/// with thousands of scans takes minutes: libjpeg-turbo's TJFLAG_LIMITSCANS does the same);
/// libjpeg's errors are caught (longjmp out of its error handler, never exit()) and come back as
/// one line; its warnings (a corrupt but decodable stream) are counted.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace sg::vision {

class JpegRegionDecoder {
 public:
  /// Most scans a progressive JPEG may have.
  static constexpr int kMaxScans = 50;

  struct Result {
    bool ok = false;
    cv::Rect decoded;   ///< the pixels written (covers the region asked for, when ok)
    std::string error;  ///< one line, when not ok
  };

  JpegRegionDecoder();
  ~JpegRegionDecoder();
  JpegRegionDecoder(const JpegRegionDecoder&) = delete;
  JpegRegionDecoder& operator=(const JpegRegionDecoder&) = delete;

  /// Decodes the part of the JPEG `data` covering `region` (clipped to the image; an empty region
  /// decodes the whole image) into `bgr`, which becomes a CV_8UC3 image of `size` (allocated as
  /// above) if it is not one already. Fails, leaving `bgr`'s pixels undefined where decoded, when
  /// the JPEG is not one libjpeg-turbo decodes or declares another size than `size`.
  Result decode(const uint8_t* data, size_t bytes, cv::Size size, cv::Rect region, cv::Mat& bgr);

  /// Warnings libjpeg-turbo gave over all decodes (corrupt data it decoded through).
  uint64_t warnings() const;
  /// Decodes that cut a part out at restart markers (jpeg_band.hpp) instead of skipping rows.
  uint64_t parts() const;

 private:
  Result decode_rows(const uint8_t* data, size_t bytes, cv::Size size, cv::Rect region,
                     cv::Mat& bgr, cv::Point origin);

  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace sg::vision
