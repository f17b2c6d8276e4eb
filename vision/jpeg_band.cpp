#include "vision/jpeg_band.hpp"

#include <algorithm>
#include <cstring>
#include <utility>
#include <vector>

namespace sg::vision {
namespace {

int be16(const uint8_t* p) { return (p[0] << 8) | p[1]; }

/// Frame headers that are not baseline or extended sequential Huffman: progressive, lossless,
/// hierarchical, arithmetic.
bool unsupported_frame(uint8_t marker) {
  return marker == 0xC2 || marker == 0xC3 || (marker >= 0xC5 && marker <= 0xC7) ||
         (marker >= 0xC9 && marker <= 0xCB) || (marker >= 0xCD && marker <= 0xCF);
}

/// The frame header's fields (SOF0/SOF1 payload `p` of `n` bytes); false when malformed.
bool read_frame(const uint8_t* p, size_t n, size_t height_at, JpegLayout& l, int& components,
                int& max_h, int& max_v) {
  if (n < 6 || p[0] != 8) return false;
  l.height = be16(p + 1), l.width = be16(p + 3), components = p[5];
  if (l.height == 0 || l.width == 0 || components < 1 || n < 6 + 3 * size_t(components))
    return false;
  for (int i = 0; i < components; ++i) {
    const int h = p[6 + 3 * i + 1] >> 4, v = p[6 + 3 * i + 1] & 15;
    if (h < 1 || h > 4 || v < 1 || v > 4) return false;
    max_h = std::max(max_h, h), max_v = std::max(max_v, v);
  }
  l.sof_height = height_at;
  return true;
}

/// The markers up to the scan's data; false for anything but one interleaved baseline scan.
bool read_headers(const uint8_t* d, size_t bytes, JpegLayout& l) {
  if (bytes < 4 || d[0] != 0xFF || d[1] != 0xD8) return false;
  int components = 0, max_h = 0, max_v = 0;
  for (size_t p = 2;;) {
    while (p + 1 < bytes && d[p] == 0xFF && d[p + 1] == 0xFF) ++p;  // fill bytes
    if (p + 4 > bytes || d[p] != 0xFF) return false;
    const uint8_t m = d[p + 1];
    const size_t length = static_cast<size_t>(be16(d + p + 2));
    if (length < 2 || p + 2 + length > bytes || (m >= 0xD0 && m <= 0xD9)) return false;
    const uint8_t* payload = d + p + 4;
    const size_t n = length - 2;
    if (unsupported_frame(m)) return false;
    if ((m == 0xC0 || m == 0xC1) && !read_frame(payload, n, p + 5, l, components, max_h, max_v))
      return false;
    if (m == 0xDD) {
      if (n < 2) return false;
      l.restart_interval = be16(payload);
    }
    if (m == 0xDA) {  // the scan: all components at once, after a frame header
      if (components == 0 || n < 1 || payload[0] != components) return false;
      l.mcu_width = components == 1 ? 8 : 8 * max_h;
      l.mcu_height = components == 1 ? 8 : 8 * max_v;
      l.scan_data = p + 2 + length;
      return true;
    }
    p += 2 + length;
  }
}

/// The RST markers in the scan's data and where it ends (at EOI); false when they do not count
/// RST0, RST1, ... RST7, RST0 ... or the data does not end in EOI.
bool read_restarts(const uint8_t* d, size_t bytes, JpegLayout& l) {
  l.restarts.clear();
  for (size_t q = l.scan_data;;) {
    const void* found = q < bytes ? std::memchr(d + q, 0xFF, bytes - q) : nullptr;
    if (found == nullptr) return false;
    const size_t i = static_cast<size_t>(static_cast<const uint8_t*>(found) - d);
    if (i + 1 >= bytes) return false;
    const uint8_t n = d[i + 1];
    if (n == 0x00 || n == 0xFF) {  // a stuffed 0xFF, or a fill byte before a marker
      q = i + (n == 0x00 ? 2 : 1);
      continue;
    }
    if (n >= 0xD0 && n <= 0xD7) {
      if (n - 0xD0 != static_cast<int>(l.restarts.size() % 8)) return false;
      l.restarts.push_back(i);
      q = i + 2;
      continue;
    }
    l.scan_end = i;
    return n == 0xD9;  // another scan, or DNL: not this layout
  }
}

}  // namespace

bool read_layout(const uint8_t* data, size_t bytes, JpegLayout& layout) {
  std::vector<size_t> kept = std::move(layout.restarts);  // its memory, for the next frame
  layout = JpegLayout{};
  layout.restarts = std::move(kept);
  if (data == nullptr || !read_headers(data, bytes, layout)) return false;
  layout.mcus_per_row = (layout.width + layout.mcu_width - 1) / layout.mcu_width;
  layout.mcu_rows = (layout.height + layout.mcu_height - 1) / layout.mcu_height;
  if (!read_restarts(data, bytes, layout)) return false;
  if (layout.restart_interval == 0) return layout.restarts.empty();
  const int64_t mcus = int64_t{layout.mcus_per_row} * layout.mcu_rows;
  const int64_t segments = (mcus + layout.restart_interval - 1) / layout.restart_interval;
  return static_cast<int64_t>(layout.restarts.size()) == segments - 1;
}

namespace {

/// [first, last) of `count` units of `step` px covering pixels [a, b), clamped to [0, size).
std::pair<int, int> span(int a, int b, int step, int size, int count) {
  const int first = std::clamp(a, 0, size - 1) / step;
  const int last = (std::clamp(b, 1, size) + step - 1) / step;
  return {first, std::clamp(last, first + 1, count)};
}

void put16(std::vector<uint8_t>& out, size_t at, int value) {
  out[at] = static_cast<uint8_t>(value >> 8), out[at + 1] = static_cast<uint8_t>(value & 0xFF);
}

}  // namespace

JpegCut cut_part(const uint8_t* data, const JpegLayout& l, int x0, int y0, int x1, int y1,
                 std::vector<uint8_t>& out) {
  // The image as a grid of segments: `across` a row of `seg_rows` MCU rows, `seg_px` px wide.
  const int across = std::max(1, l.mcus_per_row / l.restart_interval);
  const int seg_rows = std::max(1, l.restart_interval / l.mcus_per_row);
  const int seg_px = l.mcu_width * (l.mcus_per_row / across);
  const int rows_of_segments = (l.mcu_rows + seg_rows - 1) / seg_rows;
  const auto [c0, c1] = span(x0, x1, seg_px, l.width, across);
  const auto [r0, r1] = span(y0, y1, seg_rows * l.mcu_height, l.height, rows_of_segments);
  JpegCut cut;
  cut.x = c0 * seg_px, cut.y = r0 * seg_rows * l.mcu_height;
  cut.width = std::min(l.width, c1 * seg_px) - cut.x;
  cut.height = std::min(l.height, r1 * seg_rows * l.mcu_height) - cut.y;
  out.assign(data, data + l.scan_data);
  put16(out, l.sof_height, cut.height);
  put16(out, l.sof_height + 2, cut.width);
  const size_t segments = l.restarts.size() + 1;
  int markers = 0;
  for (int r = r0; r < r1; ++r) {
    for (int c = c0; c < c1; ++c) {
      const size_t k =
          static_cast<size_t>(r) * static_cast<size_t>(across) + static_cast<size_t>(c);
      if (k >= segments) break;
      if (k != static_cast<size_t>(r0 * across + c0)) {  // a marker between two segments
        out.push_back(0xFF);
        out.push_back(static_cast<uint8_t>(0xD0 + markers++ % 8));
      }
      const size_t begin = k == 0 ? l.scan_data : l.restarts[k - 1] + 2;
      const size_t end = k + 1 >= segments ? l.scan_end : l.restarts[k];
      out.insert(out.end(), data + begin, data + end);
    }
  }
  out.push_back(0xFF);
  out.push_back(0xD9);
  return cut;
}

}  // namespace sg::vision
