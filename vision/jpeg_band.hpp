#pragma once

/// A band of MCU rows cut out of a JPEG with restart markers, as a JPEG of its own, without
/// decoding anything (issue 19). A baseline JPEG has no index: to reach row y a decoder must
/// Huffman-decode every MCU above it, which costs about half of a whole decode. But a JPEG
/// whose restart interval (DRI) ends at MCU-row boundaries resets its DC predictions there, so
/// the entropy-coded segments from such a boundary on decode on their own. The band is the
/// original headers with the frame's height set to the band's, the segments of its rows with
/// their RST markers renumbered from RST0, and an EOI. sg-camera-sim's frames carry one restart
/// per MCU row (image_message.hpp's encode_image); many IP and MJPEG cameras' do too.
///
///     JpegLayout layout;
///     if (read_layout(data, bytes, layout) && layout.cuttable()) {
///       std::vector<uint8_t> part;
///       const JpegCut cut = cut_part(data, layout, x0, y0, x1, y1, part);  // widened to segments
///       ... decode `part` (cut.width x cut.height), its pixel (0, 0) is the image's (cut.x, cut.y)
///     }
///
/// Anything else — progressive or arithmetic coding, non-interleaved scans, no DRI, restarts
/// that do not fall on row boundaries, markers that do not count up as they must — is not a
/// layout read_layout() accepts, and the caller decodes the whole JPEG as it is.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sg::vision {

/// Where a baseline JPEG's parts are.
struct JpegLayout {
  int width = 0, height = 0;
  int mcu_width = 0, mcu_height = 0;   ///< pixels of one MCU (8 x max sampling factors)
  int mcus_per_row = 0, mcu_rows = 0;  ///< MCUs across and down
  int restart_interval = 0;            ///< MCUs between restarts (DRI); 0: none
  size_t sof_height = 0;               ///< offset of the frame header's height (width: + 2)
  size_t scan_data = 0;                ///< offset of the entropy-coded data
  size_t scan_end = 0;                 ///< offset of the marker after it (EOI)
  /// Offsets of the RST markers in the scan data: the k-th ends segment k.
  std::vector<size_t> restarts;

  /// True when restarts fall at MCU-row boundaries: every few rows, or several times a row at
  /// equal steps (then a band's columns can be cut too).
  bool cuttable() const {
    return restart_interval > 0 && mcus_per_row > 0 &&
           (restart_interval % mcus_per_row == 0 || mcus_per_row % restart_interval == 0);
  }
};

/// Reads the layout of a baseline, Huffman-coded, interleaved JPEG (one scan) with its restart
/// markers; false for any other JPEG or bytes, which leaves `layout` unspecified. Bounds-checked
/// throughout: any bytes are safe.
bool read_layout(const uint8_t* data, size_t bytes, JpegLayout& layout);

/// A part cut out of a JPEG: its place in the image.
struct JpegCut {
  int x = 0, y = 0, width = 0, height = 0;
};

/// Writes into `out` a JPEG of the restart segments that cover the pixels [x0, x1) x [y0, y1) of
/// the JPEG `data` with `layout` (cuttable()), and returns where that part lies in the image.
/// `out` is reused: no allocation once it has grown.
JpegCut cut_part(const uint8_t* data, const JpegLayout& layout, int x0, int y0, int x1, int y1,
                 std::vector<uint8_t>& out);

}  // namespace sg::vision
