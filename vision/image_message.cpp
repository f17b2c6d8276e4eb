#include "vision/image_message.hpp"

#include <turbojpeg.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace sg::vision {

using stereograsp::image_t;

std::optional<std::pair<int, int>> jpeg_declared_size(const std::vector<uint8_t>& jpeg) {
  struct Handle {
    tjhandle h = tjInitDecompress();
    ~Handle() {
      if (h != nullptr) tjDestroy(h);
    }
  };
  thread_local Handle decompressor;
  if (decompressor.h == nullptr || jpeg.empty()) return std::nullopt;
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(decompressor.h, jpeg.data(), static_cast<unsigned long>(jpeg.size()),
                          &width, &height, &subsampling, &colorspace) != 0) {
    return std::nullopt;
  }
  return std::pair{width, height};
}

image_t encode_image(const cv::Mat& bgr, int8_t camera, int64_t frame_number, int64_t utime,
                     bool jpeg, int jpeg_quality) {
  image_t msg{};
  msg.utime = utime;
  msg.camera = camera;
  msg.frame_number = frame_number;
  msg.width = bgr.cols;
  msg.height = bgr.rows;
  if (jpeg) {
    msg.pixel_format = image_t::FORMAT_JPEG;
    // Restart markers at equal steps of every MCU row (16 px for OpenCV's 4:2:0), every 4 MCUs
    // where the row divides so: a reader can decode a window's segments without the rest of the
    // frame (jpeg_band.hpp), for about 2 % more bytes.
    const int mcus_per_row = (bgr.cols + 15) / 16;
    int interval = mcus_per_row;
    for (int step : {4, 5, 2}) {
      if (mcus_per_row % step == 0) {
        interval = step;
        break;
      }
    }
    cv::imencode(".jpg", bgr, msg.data,
                 {cv::IMWRITE_JPEG_QUALITY, jpeg_quality, cv::IMWRITE_JPEG_RST_INTERVAL, interval});
  } else {
    msg.pixel_format = image_t::FORMAT_BGR8;
    msg.row_stride = bgr.cols * 3;
    const cv::Mat continuous = bgr.isContinuous() ? bgr : bgr.clone();
    msg.data.assign(continuous.data, continuous.data + continuous.total() * 3);
  }
  msg.size = static_cast<int32_t>(msg.data.size());
  return msg;
}

namespace {

/// Bytes a pixel takes in a raw format; 0 for JPEG or an unknown format.
int raw_channels(int format) {
  if (format == image_t::FORMAT_GRAY8) return 1;
  if (format == image_t::FORMAT_BGR8 || format == image_t::FORMAT_RGB8) return 3;
  return 0;
}

}  // namespace

std::string image_message_error(const image_t& m) {
  if (m.width <= 0 || m.height <= 0 || static_cast<int64_t>(m.width) * m.height > kMaxImagePixels)
    return "image size " + std::to_string(m.width) + "x" + std::to_string(m.height) +
           " is not valid (at most " + std::to_string(kMaxImagePixels) + " pixels)";
  if (m.size != static_cast<int32_t>(m.data.size())) return "size field does not match the data";
  if (m.pixel_format == image_t::FORMAT_JPEG) {
    const auto declared = jpeg_declared_size(m.data);
    if (!declared) return "JPEG header does not decode";
    if (declared->first != m.width || declared->second != m.height)
      return "JPEG header declares " + std::to_string(declared->first) + "x" +
             std::to_string(declared->second) + ", the message " + std::to_string(m.width) + "x" +
             std::to_string(m.height);
    return "";
  }
  const int channels = raw_channels(m.pixel_format);
  if (channels == 0) return "unknown pixel_format " + std::to_string(m.pixel_format);
  if (m.row_stride < m.width * channels ||
      static_cast<int64_t>(m.row_stride) * m.height > static_cast<int64_t>(m.data.size()))
    return std::to_string(m.width) + "x" + std::to_string(m.height) + " with row_stride " +
           std::to_string(m.row_stride) + " needs more than the " + std::to_string(m.data.size()) +
           " bytes it holds";
  return "";
}

std::optional<cv::Mat> decode_image(const image_t& m, std::string* error) {
  if (std::string e = image_message_error(m); !e.empty()) {
    if (error) *error = std::move(e);
    return std::nullopt;
  }
  if (m.pixel_format == image_t::FORMAT_JPEG) {
    cv::Mat bgr = cv::imdecode(m.data, cv::IMREAD_COLOR);
    if (bgr.empty() || bgr.cols != m.width || bgr.rows != m.height) {
      if (error)
        *error =
            bgr.empty() ? "JPEG data does not decode" : "JPEG size differs from width x height";
      return std::nullopt;
    }
    return bgr;
  }
  const int channels = raw_channels(m.pixel_format);
  const cv::Mat view(m.height, m.width, channels == 1 ? CV_8U : CV_8UC3,
                     const_cast<uint8_t*>(m.data.data()), static_cast<size_t>(m.row_stride));
  cv::Mat bgr;
  if (m.pixel_format == image_t::FORMAT_GRAY8)
    cv::cvtColor(view, bgr, cv::COLOR_GRAY2BGR);
  else if (m.pixel_format == image_t::FORMAT_RGB8)
    cv::cvtColor(view, bgr, cv::COLOR_RGB2BGR);
  else
    bgr = view.clone();
  return bgr;
}

stereograsp::blob_t to_blob_t(const Observation& o, int8_t camera, int64_t frame_number,
                              int64_t utime) {
  stereograsp::blob_t b{};
  b.utime = utime;
  b.camera = camera;
  b.frame_number = frame_number;
  b.found = o.found;
  b.mode = o.tracking ? stereograsp::blob_t::MODE_TRACKING : stereograsp::blob_t::MODE_FULL_FRAME;
  const Blob& blob = o.blob;
  b.centroid[0] = blob.centroid.x, b.centroid[1] = blob.centroid.y;
  b.area = blob.area;
  b.major_axis = blob.major_axis;
  b.minor_axis = blob.minor_axis;
  b.orientation = blob.orientation;
  for (int i = 0; i < 2; ++i) {
    b.major_axis_ends[i][0] = blob.major_axis_ends[static_cast<size_t>(i)].x;
    b.major_axis_ends[i][1] = blob.major_axis_ends[static_cast<size_t>(i)].y;
    b.minor_axis_ends[i][0] = blob.minor_axis_ends[static_cast<size_t>(i)].x;
    b.minor_axis_ends[i][1] = blob.minor_axis_ends[static_cast<size_t>(i)].y;
  }
  b.bounding_box[0] = blob.bounding_box.x, b.bounding_box[1] = blob.bounding_box.y;
  b.bounding_box[2] = blob.bounding_box.x + blob.bounding_box.width;
  b.bounding_box[3] = blob.bounding_box.y + blob.bounding_box.height;
  b.search_window[0] = o.window.x, b.search_window[1] = o.window.y;
  b.search_window[2] = o.window.width, b.search_window[3] = o.window.height;
  b.num_regions = o.num_regions;
  b.misses = o.misses;
  b.centre[0] = o.found ? o.centre.x : std::nan(""),
  b.centre[1] = o.found ? o.centre.y : std::nan("");
  b.radius = o.found ? o.radius : std::nan("");
  b.fit_support = o.found ? o.fit_support : std::nan("");
  b.fit_arc = o.found ? static_cast<int64_t>(o.arc) : 0;
  b.confidence = o.confidence;
  b.candidates = o.candidates;
  return b;
}

}  // namespace sg::vision
