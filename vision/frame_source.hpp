#pragma once

/// sg-vision's frames from outside the bus: two video files, two folders of images (paired by
/// name order, list_images()), or two V4L2 cameras; and the loop that plays them through a
/// StereoPublisher.
///
///     sg::vision::FrameSource source({.kind = "images", .left = "dirL", .right = "dirR"});
///     sg::vision::play_frames(source, publisher, {.fps = 30});

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "vision/stereo_publisher.hpp"

namespace sg::vision {

class FrameSource {
 public:
  struct Settings {
    std::string kind = "video";     ///< "video", "images" or "v4l2"
    std::string left, right;        ///< video files, image folders or V4L2 devices
    int width = 640, height = 480;  ///< v4l2: the image size to ask for
    double fps = 30;                ///< v4l2: the rate to ask for
  };

  /// Opens both; throws std::runtime_error naming what cannot be opened, or folders holding
  /// different numbers of images.
  explicit FrameSource(const Settings& settings);

  /// The next pair; false at the end (or after a file ends). Throws when live cameras stop
  /// delivering (five attempts, 100 ms apart).
  bool next(cv::Mat& left, cv::Mat& right);

  /// Live cameras (capture time is the clock), not files (capture time is the frame's place).
  bool live() const { return settings_.kind == "v4l2"; }

 private:
  static cv::Mat read(const std::string& path);

  Settings settings_;
  cv::VideoCapture capture_[2];
  std::vector<std::string> files_[2];
  size_t index_ = 0;
};

struct PlaySettings {
  double rate_hz = 0;      ///< pace to this many pairs a second (0: as fast as possible)
  double fps = 30;         ///< files: the recording's frame rate, for capture times
  int64_t max_frames = 0;  ///< stop after this many pairs (0: no limit)
};

/// Plays `source` through `vision` until it ends, max_frames, or sg::shutdown_requested(); each
/// pair stamped with its capture time: the clock for live cameras, start + k / rate for files.
/// Prints the publisher's summary at the end.
void play_frames(FrameSource& source, StereoPublisher& vision, const PlaySettings& settings);

}  // namespace sg::vision
