#include "vision/segmentation.hpp"

#include <stdexcept>

namespace sg::vision {

Segmenter::Segmenter(cv::Size max_size) {
  const size_t pixels = static_cast<size_t>(max_size.area());
  labels_.resize(pixels);
  parent_.resize(pixels / 2 + 2);  // 8-connectivity: at most one new label every other pixel
  sums_.resize(pixels / 2 + 2);
}

int32_t Segmenter::find(int32_t label) {
  while (parent_[static_cast<size_t>(label)] != label) {
    parent_[static_cast<size_t>(label)] =
        parent_[static_cast<size_t>(parent_[static_cast<size_t>(label)])];  // path halving
    label = parent_[static_cast<size_t>(label)];
  }
  return label;
}

int32_t Segmenter::unite(int32_t a, int32_t b) {
  a = find(a), b = find(b);
  if (a == b) return a;
  if (a < b) std::swap(a, b);
  parent_[static_cast<size_t>(a)] = b;
  return b;
}

Segmentation Segmenter::run(const cv::Mat& bgr, const cv::Rect& window,
                            const ColorDetector& detector, int min_area) {
  CV_Assert(bgr.type() == CV_8UC3);
  const cv::Rect w = window & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (static_cast<size_t>(w.area()) > labels_.size())
    throw std::invalid_argument("Segmenter: window larger than the size it was made for");
  const int ww = w.width, wh = w.height;
  int32_t next = 1;
  parent_[0] = 0;
  // Pass 1: detect and label; a pixel joins its already-labelled 8-neighbours above and left.
  for (int y = 0; y < wh; ++y) {
    const uint8_t* in = bgr.ptr<uint8_t>(w.y + y) + 3 * w.x;
    int32_t* row = labels_.data() + static_cast<size_t>(y) * ww;
    const int32_t* up = y > 0 ? row - ww : nullptr;
    for (int x = 0; x < ww; ++x, in += 3) {
      if (!detector.is_object(in)) {
        row[x] = 0;
        continue;
      }
      int32_t label = x > 0 ? row[x - 1] : 0;
      if (up != nullptr) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (x + dx < 0 || x + dx >= ww) continue;
          const int32_t n = up[x + dx];
          if (n != 0) label = label == 0 ? n : unite(label, n);
        }
      }
      if (label == 0) {
        label = next++;
        parent_[static_cast<size_t>(label)] = label;
      }
      row[x] = label;
    }
  }
  // Pass 2: moments per region (image coordinates), counted at each region's root.
  for (int32_t i = 1; i < next; ++i) sums_[static_cast<size_t>(i)] = RawMoments{};
  for (int y = 0; y < wh; ++y) {
    const int32_t* row = labels_.data() + static_cast<size_t>(y) * ww;
    for (int x = 0; x < ww; ++x) {
      if (row[x] != 0) sums_[static_cast<size_t>(find(row[x]))].add(w.x + x, w.y + y);
    }
  }
  Segmentation result;
  for (int32_t i = 1; i < next; ++i) {
    if (parent_[static_cast<size_t>(i)] != i) continue;
    ++result.num_regions;
    const RawMoments& m = sums_[static_cast<size_t>(i)];
    if (m.m00 >= min_area && m.m00 > result.largest.m00) {
      result.largest = m;
      result.found = true;
    }
  }
  return result;
}

}  // namespace sg::vision
