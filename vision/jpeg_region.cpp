#include "vision/jpeg_region.hpp"

// clang-format off
#include <cstdio>   // jpeglib.h needs FILE and size_t first
#include <jpeglib.h>
// clang-format on

#include <algorithm>
#include <csetjmp>
#include <vector>

#include "vision/jpeg_band.hpp"

namespace sg::vision {
namespace {

/// libjpeg's error manager, extended with where to jump to instead of exit().
struct ErrorManager {
  jpeg_error_mgr pub;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
  uint64_t warnings;
};

[[noreturn]] void on_error(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

void on_message(j_common_ptr cinfo, int level) {  // never printed: counted
  if (level < 0) ++reinterpret_cast<ErrorManager*>(cinfo->err)->warnings;
}

/// A progressive JPEG with more than kMaxScans scans is refused as it is read.
void on_progress(j_common_ptr cinfo) {
  auto* d = reinterpret_cast<j_decompress_ptr>(cinfo);
  if (d->progressive_mode && d->input_scan_number > JpegRegionDecoder::kMaxScans) {
    auto* e = reinterpret_cast<ErrorManager*>(cinfo->err);
    std::snprintf(e->message, sizeof e->message, "progressive JPEG with more than %d scans",
                  JpegRegionDecoder::kMaxScans);
    std::longjmp(e->jump, 1);
  }
}

/// Pixels around a region that a part cut at restart markers also covers: the upsampling of a
/// subsampled chroma reads one chroma sample (2 px) beyond a pixel, and a part's own edge is
/// upsampled from replicated samples. Twice that reach (a test checks the pixels bit for bit).
constexpr int kCutMargin = 4;

/// `region` clipped to the image and widened by `mx`, `my` px on each side (empty: all of it).
cv::Rect widened(cv::Rect region, cv::Size size, int mx, int my) {
  const cv::Rect all(0, 0, size.width, size.height);
  region &= all;
  if (region.empty()) return all;
  const int x0 = std::max(0, region.x - mx), y0 = std::max(0, region.y - my);
  const int x1 = std::min(size.width, region.br().x + mx);
  const int y1 = std::min(size.height, region.br().y + my);
  return {x0, y0, x1 - x0, y1 - y0};
}

/// A BGR frame of `size` whose rows start 3 bytes past a 32-byte boundary, 3 x (a multiple of 32)
/// bytes apart. libjpeg-turbo's SIMD colour conversion writes an output row that starts on a 16- or
/// 32-byte boundary with non-temporal stores (`vmovntdq`, simd/x86_64/jdcolext-avx2.asm), which
/// bypass the cache: a window's short rows written so cost more than they save, and the tracker
/// then reads them from memory. A cropped row starts 3 x (a multiple of 8) bytes further: an odd
/// address, never on such a boundary.
void allocate_frame(cv::Mat& bgr, cv::Size size) {
  const int padded = (size.width + 1 + 31) / 32 * 32;  // px
  const cv::Mat rows(size.height, padded, CV_8UC3);    // OpenCV aligns it to 64 bytes
  bgr = rows(cv::Rect(1, 0, size.width, size.height));
}

}  // namespace

struct JpegRegionDecoder::State {
  jpeg_decompress_struct cinfo{};
  ErrorManager error{};
  jpeg_progress_mgr progress{};
  JpegLayout layout;          // of the last JPEG, its vector reused
  std::vector<uint8_t> part;  // the last part cut, reused
  uint64_t parts = 0;
};

JpegRegionDecoder::JpegRegionDecoder() : state_(std::make_unique<State>()) {
  jpeg_decompress_struct& c = state_->cinfo;
  c.err = jpeg_std_error(&state_->error.pub);
  state_->error.pub.error_exit = on_error;
  state_->error.pub.emit_message = on_message;
  jpeg_create_decompress(&c);  // cannot fail short of memory, which on_error would not survive
  state_->progress.progress_monitor = on_progress;
  c.progress = &state_->progress;
}

JpegRegionDecoder::~JpegRegionDecoder() { jpeg_destroy_decompress(&state_->cinfo); }

uint64_t JpegRegionDecoder::warnings() const { return state_->error.warnings; }

namespace {

std::string declared_error(int width, int height, cv::Size size) {
  return "JPEG header declares " + std::to_string(width) + "x" + std::to_string(height) +
         ", the message " + std::to_string(size.width) + "x" + std::to_string(size.height);
}

}  // namespace

JpegRegionDecoder::Result JpegRegionDecoder::decode(const uint8_t* data, size_t bytes,
                                                    cv::Size size, cv::Rect region, cv::Mat& bgr) {
  if (data == nullptr || bytes == 0) return {false, {}, "empty JPEG"};
  if (bgr.type() != CV_8UC3 || bgr.size() != size) allocate_frame(bgr, size);
  JpegLayout& layout = state_->layout;
  const cv::Rect all(0, 0, size.width, size.height);
  if (!(region & all).empty() && read_layout(data, bytes, layout) && layout.cuttable()) {
    if (layout.width != size.width || layout.height != size.height)
      return {false, {}, declared_error(layout.width, layout.height, size)};
    const cv::Rect want = widened(region, size, kCutMargin, kCutMargin);
    if (want != all) {  // only the part's own restart segments are decoded at all
      const JpegCut cut =
          cut_part(data, layout, want.x, want.y, want.br().x, want.br().y, state_->part);
      ++state_->parts;
      const cv::Point origin(cut.x, cut.y);
      return decode_rows(state_->part.data(), state_->part.size(), {cut.width, cut.height},
                         region - origin, bgr, origin);
    }
  }
  return decode_rows(data, bytes, size, region, bgr, {0, 0});
}

JpegRegionDecoder::Result JpegRegionDecoder::decode_rows(const uint8_t* data, size_t bytes,
                                                         cv::Size size, cv::Rect region,
                                                         cv::Mat& bgr, cv::Point origin) {
  Result r;
  jpeg_decompress_struct& c = state_->cinfo;
  // Only plain data lives across the setjmp: nothing with a destructor is skipped by longjmp.
  if (setjmp(state_->error.jump)) {
    jpeg_abort_decompress(&c);
    r.error = std::string("JPEG does not decode: ") + state_->error.message;
    return r;
  }
  jpeg_mem_src(&c, data, static_cast<unsigned long>(bytes));
  jpeg_read_header(&c, TRUE);
  if (static_cast<int>(c.image_width) != size.width ||
      static_cast<int>(c.image_height) != size.height) {
    r.error =
        declared_error(static_cast<int>(c.image_width), static_cast<int>(c.image_height), size);
    jpeg_abort_decompress(&c);
    return r;
  }
  c.out_color_space = JCS_EXT_BGR;
  jpeg_start_decompress(&c);
  // The upsampling of the region's edge reads its neighbours: a margin as for a cut; from the top
  // of an iMCU row, as skipping rows inside one costs more than converting them.
  cv::Rect want = widened(region, size, kCutMargin, kCutMargin);
  const int imcu_rows = c.max_v_samp_factor * DCTSIZE, top = want.y / imcu_rows * imcu_rows;
  want.height += want.y - top, want.y = top;
  JDIMENSION x = static_cast<JDIMENSION>(want.x), width = static_cast<JDIMENSION>(want.width);
  if (want.width < size.width) jpeg_crop_scanline(&c, &x, &width);  // x moves left to an iMCU
  if (want.y > 0) jpeg_skip_scanlines(&c, static_cast<JDIMENSION>(want.y));
  while (static_cast<int>(c.output_scanline) < want.br().y) {
    JSAMPROW out = bgr.ptr<uint8_t>(origin.y + static_cast<int>(c.output_scanline)) +
                   3 * (origin.x + static_cast<int>(x));
    if (jpeg_read_scanlines(&c, &out, 1) != 1) {  // cannot happen with a memory source
      jpeg_abort_decompress(&c);
      r.error = "JPEG decoder gave no scanline";
      return r;
    }
  }
  if (c.output_scanline == c.output_height)
    jpeg_finish_decompress(&c);
  else
    jpeg_abort_decompress(&c);
  r.ok = true;
  r.decoded = cv::Rect(origin.x + static_cast<int>(x), origin.y + want.y, static_cast<int>(width),
                       want.height);
  return r;
}

uint64_t JpegRegionDecoder::parts() const { return state_->parts; }

}  // namespace sg::vision
