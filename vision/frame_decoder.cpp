#include "vision/frame_decoder.hpp"

#include "vision/image_message.hpp"

namespace sg::vision {

using stereograsp::image_t;

const cv::Mat* FrameDecoder::decode(const image_t& m, cv::Rect region, std::string* error) {
  auto fail = [&](const std::string& what) -> const cv::Mat* {
    if (error) *error = what;
    return nullptr;
  };
  if (m.pixel_format != image_t::FORMAT_JPEG) {  // raw: converted whole
    std::optional<cv::Mat> raw = decode_image(m, error);
    if (!raw) return nullptr;
    frame_ = std::move(*raw);
    decoded_ = cv::Rect({}, frame_.size());
    return &frame_;
  }
  if (const std::string e = image_message_error(m); !e.empty()) return fail(e);
  if (mode_ == Mode::kFull) region = {};
  const JpegRegionDecoder::Result r =
      jpeg_.decode(m.data.data(), m.data.size(), {m.width, m.height}, region, frame_);
  if (!r.ok) {
    decoded_ = {};
    return fail(r.error);
  }
  decoded_ = r.decoded;
  return &frame_;
}

}  // namespace sg::vision
