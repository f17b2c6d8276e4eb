#include "vision/stereo_publisher.hpp"

#include <cstdio>
#include <utility>

#include "common/clock.hpp"
#include "vision/image_message.hpp"

namespace sg::vision {

StereoPublisher::StereoPublisher(sg::Bus& bus, const VisionSettings& settings, cv::Size size,
                                 std::optional<StereoCalibration> calibration, bool publish_images)
    : bus_(bus),
      step_(settings.tracker, size, std::move(calibration), settings.match),
      publish_images_(publish_images) {}

StereoPublisher::Published StereoPublisher::process(const cv::Mat& left, const cv::Mat& right,
                                                    int64_t frame_number, int64_t utime) {
  if (publish_images_) {
    const cv::Mat* images[2] = {&left, &right};
    for (int i = 0; i < 2; ++i)
      bus_.publish(i == 0 ? "CAMERA_LEFT" : "CAMERA_RIGHT",
                   encode_image(*images[i], static_cast<int8_t>(i), frame_number, utime, true));
  }
  const StereoOutput out = step_.process(left, right, frame_number, utime);
  Published published;
  if (out.position) {
    bus_.publish("OBJECT_POSITION", *out.position);
    published = {bus_.last_handed_utime(), sg::now_utime()};
  }
  bus_.publish("BLOB_LEFT", out.blob[0]);
  bus_.publish("BLOB_RIGHT", out.blob[1]);
  return published;
}

void StereoPublisher::report(uint64_t unmatched, uint64_t bad_images) const {
  const StereoCounts& c = step_.counts();
  auto pct = [&](uint64_t n) {
    return c.pairs ? 100.0 * static_cast<double>(n) / static_cast<double>(c.pairs) : 0.0;
  };
  std::printf(
      "processed %llu stereo frames: ball found left %.1f%%, right %.1f%%; tracking mode "
      "left %.1f%%, right %.1f%%; %llu unmatched frames, %llu bad images\n",
      static_cast<unsigned long long>(c.pairs), pct(c.found[0]), pct(c.found[1]),
      pct(c.tracking[0]), pct(c.tracking[1]), static_cast<unsigned long long>(unmatched),
      static_cast<unsigned long long>(bad_images));
}

}  // namespace sg::vision
