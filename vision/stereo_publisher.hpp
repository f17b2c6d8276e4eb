#pragma once

/// sg-vision's output: runs the stereo step (stereo_step.hpp, sections 5.1-5.4) on each pair and
/// publishes what it found, OBJECT_POSITION first (when the ball is placed in 3D), then
/// BLOB_LEFT and BLOB_RIGHT, so that a viewer drawing on the blobs has the frame's position too.
///
///     sg::vision::StereoPublisher vision(bus, settings, {640, 480}, calibration, false);
///     const auto sent = vision.process(left, right, frame_number, capture_utime);
///     if (sent.handed != 0) latency.add(sent.handed - second_image_received_utime);

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>

#include "common/bus.hpp"
#include "vision/calibration_file.hpp"
#include "vision/stereo_step.hpp"
#include "vision/vision_config.hpp"

namespace sg::vision {

class StereoPublisher {
 public:
  /// `publish_images`: republish each pair as JPEG CAMERA_LEFT/RIGHT first (frames from cameras
  /// or files, not from the bus).
  StereoPublisher(sg::Bus& bus, const VisionSettings& settings, cv::Size size,
                  std::optional<StereoCalibration> calibration, bool publish_images);

  /// When a pair's OBJECT_POSITION went out (sg::now_utime(); 0 when there was none): handed to
  /// the bus (sg::Bus::last_handed_utime()), and the bus's publish() returned.
  struct Published {
    int64_t handed = 0, returned = 0;
  };

  /// Tracks a pair (BGR) captured at `utime` and publishes OBJECT_POSITION (when seen), then
  /// BLOB_LEFT and BLOB_RIGHT.
  Published process(const cv::Mat& left, const cv::Mat& right, int64_t frame_number, int64_t utime);

  /// Where camera `camera` (0 left, 1 right) will look in its next frame of size `frame`.
  cv::Rect next_window(size_t camera, cv::Size frame) const {
    return step_.next_window(camera, frame);
  }

  /// Prints the summary line: pairs, how often each camera found the ball and tracked it.
  void report(uint64_t unmatched, uint64_t bad_images) const;

 private:
  sg::Bus& bus_;
  StereoStep step_;
  bool publish_images_;
};

}  // namespace sg::vision
