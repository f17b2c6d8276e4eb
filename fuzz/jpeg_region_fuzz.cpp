// Drives sg-vision's JPEG path (vision/jpeg_region.hpp, vision/jpeg_band.hpp) with any bytes, as
// a hostile bus delivers a CAMERA_LEFT message's data: the first 4 bytes pick the region, the
// rest is the JPEG, of the size its own header declares (at most 1024 x 1024 here, to bound the
// run). Asserts, beyond not crashing and not reading outside the input:
//  - a layout read_layout() accepts lies inside the input (scan data before its end, restart
//    markers in order between them), and cut_part() returns a part inside the image;
//  - when the whole image and the region both decode without a libjpeg-turbo warning, the
//    region's pixels are the whole decode's, bit for bit.

#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <turbojpeg.h>
#include <vector>

#include "fuzz/fuzz_support.hpp"
#include "vision/jpeg_band.hpp"
#include "vision/jpeg_region.hpp"

namespace vision = sg::vision;

namespace {

void check_layout(const uint8_t* data, size_t size, const vision::JpegLayout& l, cv::Rect r) {
  SG_FUZZ_CHECK(l.scan_data <= l.scan_end && l.scan_end < size, "scan data outside the input");
  size_t last = l.scan_data;
  for (const size_t at : l.restarts) {
    SG_FUZZ_CHECK(at >= last && at < l.scan_end, "restart marker out of order");
    last = at + 2;
  }
  if (!l.cuttable()) return;
  std::vector<uint8_t> part;
  const vision::JpegCut cut = vision::cut_part(data, l, r.x, r.y, r.br().x, r.br().y, part);
  SG_FUZZ_CHECK(cut.x >= 0 && cut.y >= 0 && cut.width > 0 && cut.height > 0 &&
                    cut.x + cut.width <= l.width && cut.y + cut.height <= l.height,
                "part %d,%d %dx%d outside %dx%d", cut.x, cut.y, cut.width, cut.height, l.width,
                l.height);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* input, size_t size) {
  if (size < 5) return 0;
  const cv::Rect region(input[0] * 4, input[1] * 4, input[2] + 1, input[3] + 1);
  const uint8_t* data = input + 4;
  const size_t bytes = size - 4;
  int width = 0, height = 0, subsampling = 0, colourspace = 0;
  tjhandle tj = tjInitDecompress();
  const bool header = tjDecompressHeader3(tj, data, static_cast<unsigned long>(bytes), &width,
                                          &height, &subsampling, &colourspace) == 0;
  tjDestroy(tj);
  vision::JpegLayout layout;
  if (vision::read_layout(data, bytes, layout)) check_layout(data, bytes, layout, region);
  if (!header || width <= 0 || height <= 0 || width > 1024 || height > 1024) return 0;
  vision::JpegRegionDecoder whole_decoder, region_decoder;
  cv::Mat whole, part;
  const auto a = whole_decoder.decode(data, bytes, {width, height}, {}, whole);
  const auto b = region_decoder.decode(data, bytes, {width, height}, region, part);
  const cv::Rect inside = region & cv::Rect(0, 0, width, height);
  if (a.ok && b.ok && whole_decoder.warnings() == 0 && region_decoder.warnings() == 0 &&
      !inside.empty()) {
    SG_FUZZ_CHECK(cv::norm(whole(inside), part(inside), cv::NORM_INF) == 0,
                  "region %d,%d %dx%d differs from the whole decode", inside.x, inside.y,
                  inside.width, inside.height);
  }
  return 0;
}
