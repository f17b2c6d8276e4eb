#include "vision/segmentation.hpp"

#include <bit>
#include <cstring>
#include <stdexcept>

#include "vision/channel_sums.hpp"

namespace sg::vision {

Segmenter::Segmenter(cv::Size max_size, Kernel kernel) : max_size_(max_size), kernel_(kernel) {
  const size_t pixels = static_cast<size_t>(max_size.area());
  const size_t rows = static_cast<size_t>(max_size.height);
  // 8-connectivity: at most one new label (one run) every other pixel, half a pixel more a row
  const size_t labels = pixels / 2 + rows + 2;
  if (kernel_ == Kernel::kPixels) labels_.resize(pixels);
  parent_.resize(labels);
  sums_.resize(labels);
  mask_.resize(static_cast<size_t>((max_size.width + 2) * (max_size.height + 2)));
  if (kernel_ == Kernel::kRuns) {
    runs_.resize(labels);
    row_start_.resize(rows + 1);
    bits_per_row_ = static_cast<size_t>(max_size.width) / 64 + 1;
    window_bits_.resize(bits_per_row_ * rows);
  }
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

namespace {

void add_pixel(Region& r, int x, int y, const uint8_t* bgr) {
  r.moments.add(x, y);
  r.x_min = std::min(r.x_min, x), r.x_max = std::max(r.x_max, x);
  r.y_min = std::min(r.y_min, y), r.y_max = y;  // rows come in order
  r.sum_b += bgr[0], r.sum_g += bgr[1], r.sum_r += bgr[2];
}

void merge(Region& into, const Region& r) {
  RawMoments& m = into.moments;
  m.m00 += r.moments.m00, m.m10 += r.moments.m10, m.m01 += r.moments.m01;
  m.m20 += r.moments.m20, m.m02 += r.moments.m02, m.m11 += r.moments.m11;
  into.x_min = std::min(into.x_min, r.x_min), into.x_max = std::max(into.x_max, r.x_max);
  into.y_min = std::min(into.y_min, r.y_min), into.y_max = std::max(into.y_max, r.y_max);
  into.sum_b += r.sum_b, into.sum_g += r.sum_g, into.sum_r += r.sum_r;
}

}  // namespace

// One pass: detect and label (a pixel joins its already-labelled 8-neighbours above and left),
// summing moments, extent and colour per provisional label as it goes.
void Segmenter::label_window(const cv::Mat& bgr, const ColorDetector& detector) {
  const cv::Rect& w = window_;
  const int ww = w.width;
  next_ = 1;
  parent_[0] = 0;
  for (int y = 0; y < w.height; ++y) {
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
        label = next_++;
        parent_[static_cast<size_t>(label)] = label;
        sums_[static_cast<size_t>(label)] =
            Region{{}, w.x + x, w.y + y, w.x + x, w.y + y, 0, 0, 0, label};
      }
      row[x] = label;
      add_pixel(sums_[static_cast<size_t>(label)], w.x + x, w.y + y, in);
    }
  }
}

namespace {

/// The first x in [x, n) where the row's bit is `set` (n when none), 64 pixels a step.
int next_where(const uint64_t* bits, int x, int n, bool set) {
  const uint64_t flip = set ? 0 : ~uint64_t{0};
  while (x < n) {
    const uint64_t v = (bits[x / 64] ^ flip) >> (x % 64);
    if (v != 0) return std::min(n, x + std::countr_zero(v));
    x = (x / 64 + 1) * 64;
  }
  return n;
}

/// Sum of k^2 for k in [0, x].
int64_t squares_to(int64_t x) { return x * (x + 1) * (2 * x + 1) / 6; }

/// A run's pixels [xa, xb] of image row y: moments in closed form, extent, colour (`bgr` the
/// run's first pixel, `readable` pixels from it in the row).
void add_run(Region& r, int64_t xa, int64_t xb, int64_t y, const uint8_t* bgr, int readable) {
  const int64_t n = xb - xa + 1, sum_x = (xa + xb) * n / 2;
  RawMoments& m = r.moments;
  m.m00 += n, m.m10 += sum_x, m.m01 += n * y;
  m.m20 += squares_to(xb) - squares_to(xa - 1), m.m02 += n * y * y, m.m11 += y * sum_x;
  r.x_min = std::min(r.x_min, static_cast<int>(xa)),
  r.x_max = std::max(r.x_max, static_cast<int>(xb));
  r.y_max = static_cast<int>(y);
  add_channel_sums(bgr, static_cast<size_t>(n), static_cast<size_t>(std::max(0, readable)),
                   &r.sum_b, &r.sum_g, &r.sum_r);
}

}  // namespace

// The label of a run [x0, x1) joining the runs above it that touch it (8-connected: an above run
// [a, b) touches when a <= x1 and b >= x0); `above` moves past the runs that end too far left.
int32_t Segmenter::label_of_run(int x0, int x1, size_t& above, size_t above_end) {
  while (above < above_end && runs_[above].x1 < x0) ++above;
  int32_t label = 0;
  for (size_t q = above; q < above_end && runs_[q].x0 <= x1; ++q)
    label = label == 0 ? runs_[q].label : unite(label, runs_[q].label);
  return label;
}

// The window classified in one call; then row by row: find the runs, label them against the
// row above, sum them.
void Segmenter::label_runs(const cv::Mat& bgr, const ColorDetector& detector) {
  const cv::Rect& w = window_;
  next_ = 1;
  parent_[0] = 0;
  size_t count = 0;
  const ClassifyTally tally = detector.classify_rows(
      {bgr.ptr<uint8_t>(w.y) + 3 * w.x, bgr.step[0], static_cast<size_t>(w.width),
       static_cast<size_t>(w.height), static_cast<size_t>(bgr.cols - w.x), window_bits_.data(),
       bits_per_row_, first_bound_});
  first_bound_ = tally.next_first_bound(first_bound_);
  for (int y = 0; y < w.height; ++y) {
    const uint8_t* in = bgr.ptr<uint8_t>(w.y + y) + 3 * w.x;
    const uint64_t* row_bits = window_bits_.data() + static_cast<size_t>(y) * bits_per_row_;
    size_t above = y > 0 ? row_start_[static_cast<size_t>(y - 1)] : 0;
    const size_t above_end = count;
    row_start_[static_cast<size_t>(y)] = count;
    for (int x0 = next_where(row_bits, 0, w.width, true); x0 < w.width;
         x0 = next_where(row_bits, x0, w.width, true)) {
      const int x1 = next_where(row_bits, x0, w.width, false);
      int32_t label = y > 0 ? label_of_run(x0, x1, above, above_end) : 0;
      if (label == 0) {
        label = next_++;
        parent_[static_cast<size_t>(label)] = label;
        sums_[static_cast<size_t>(label)] =
            Region{{}, w.x + x0, w.y + y, w.x + x0, w.y + y, 0, 0, 0, label};
      }
      runs_[count++] = {x0, x1, label};
      add_run(sums_[static_cast<size_t>(label)], w.x + x0, w.x + x1 - 1, w.y + y, in + 3 * x0,
              bgr.cols - w.x - x0);
      x0 = x1;
    }
  }
  row_start_[static_cast<size_t>(w.height)] = count;
}

// A label's parent is never larger than itself, so one forward pass points each at its root;
// each provisional label's sums then go to its root.
void Segmenter::sum_regions() {
  for (int32_t i = 1; i < next_; ++i) {
    const size_t p =
        static_cast<size_t>(parent_[static_cast<size_t>(parent_[static_cast<size_t>(i)])]);
    parent_[static_cast<size_t>(i)] = static_cast<int32_t>(p);
    if (p != static_cast<size_t>(i)) merge(sums_[p], sums_[static_cast<size_t>(i)]);
  }
}

// Keeps `region` among the kMaxRegions largest, largest first.
void Segmenter::keep_candidate(Segmentation& s, const Region& region) const {
  int at = s.num_candidates;
  while (at > 0 && s.regions[static_cast<size_t>(at - 1)].moments.m00 < region.moments.m00) --at;
  if (at >= Segmentation::kMaxRegions) return;
  const int last = std::min(s.num_candidates, Segmentation::kMaxRegions - 1);
  for (int k = last; k > at; --k)
    s.regions[static_cast<size_t>(k)] = s.regions[static_cast<size_t>(k - 1)];
  s.regions[static_cast<size_t>(at)] = region;
  s.num_candidates = std::min(s.num_candidates + 1, Segmentation::kMaxRegions);
}

Segmentation Segmenter::run(const cv::Mat& bgr, const cv::Rect& window,
                            const ColorDetector& detector, int min_area) {
  CV_Assert(bgr.type() == CV_8UC3);
  window_ = window & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (window_.width > max_size_.width || window_.height > max_size_.height)
    throw std::invalid_argument("Segmenter: window larger than the size it was made for");
  if (kernel_ == Kernel::kRuns)
    label_runs(bgr, detector);
  else
    label_window(bgr, detector);
  sum_regions();
  Segmentation result;
  for (int32_t i = 1; i < next_; ++i) {
    if (parent_[static_cast<size_t>(i)] != i) continue;
    ++result.num_regions;
    const Region& r = sums_[static_cast<size_t>(i)];
    if (r.moments.m00 < min_area) continue;
    if (r.moments.m00 > result.largest.m00) result.largest = r.moments;
    result.found = true;
    keep_candidate(result, r);
  }
  return result;
}

cv::Mat Segmenter::mask_of(const Region& region) {
  const cv::Rect box =
      (cv::Rect(region.x_min - 1, region.y_min - 1, region.x_max - region.x_min + 3,
                region.y_max - region.y_min + 3)) &
      window_;
  mask_origin_ = box.tl();
  cv::Mat mask(box.height, box.width, CV_8UC1, mask_.data());
  if (box.empty()) return mask;
  if (kernel_ == Kernel::kRuns) {
    paint_runs(region, box, mask);
    return mask;
  }
  for (int y = 0; y < box.height; ++y) {
    const int32_t* row = labels_.data() +
                         static_cast<size_t>(box.y - window_.y + y) * window_.width +
                         (box.x - window_.x);
    uint8_t* out = mask.ptr<uint8_t>(y);
    for (int x = 0; x < box.width; ++x) {
      out[x] = row[x] != 0 && parent_[static_cast<size_t>(row[x])] == region.label ? 255 : 0;
    }
  }
  return mask;
}

// The region's runs (after sum_regions(), every run's label points at its root) into `mask`.
void Segmenter::paint_runs(const Region& region, const cv::Rect& box, cv::Mat& mask) const {
  mask.setTo(0);
  for (int y = 0; y < box.height; ++y) {
    const size_t row = static_cast<size_t>(box.y - window_.y + y);
    uint8_t* out = mask.ptr<uint8_t>(y);
    for (size_t k = row_start_[row]; k < row_start_[row + 1]; ++k) {
      const Run& r = runs_[k];
      if (parent_[static_cast<size_t>(r.label)] != region.label) continue;
      const int a = std::max(r.x0 + window_.x, box.x), b = std::min(r.x1 + window_.x, box.br().x);
      if (a < b) std::memset(out + (a - box.x), 255, static_cast<size_t>(b - a));
    }
  }
}

}  // namespace sg::vision
