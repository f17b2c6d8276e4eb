#include "vision/frame_source.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <thread>

#include "common/clock.hpp"
#include "common/shutdown.hpp"
#include "vision/image_folder.hpp"

namespace sg::vision {

FrameSource::FrameSource(const Settings& settings) : settings_(settings) {
  const Settings& s = settings_;
  if (s.left.empty() || s.right.empty())
    throw std::runtime_error("--left and --right are required for --source " + s.kind);
  if (s.kind == "images") {
    files_[0] = list_images(s.left);
    files_[1] = list_images(s.right);
    if (files_[0].size() != files_[1].size())
      throw std::runtime_error("--left has " + std::to_string(files_[0].size()) +
                               " images but --right has " + std::to_string(files_[1].size()));
    return;
  }
  for (int i = 0; i < 2; ++i) {
    const std::string& name = i == 0 ? s.left : s.right;
    if (s.kind == "v4l2") {
      capture_[i].open(name, cv::CAP_V4L2);
      if (capture_[i].isOpened()) {
        capture_[i].set(cv::CAP_PROP_FRAME_WIDTH, s.width);
        capture_[i].set(cv::CAP_PROP_FRAME_HEIGHT, s.height);
        capture_[i].set(cv::CAP_PROP_FPS, s.fps);
      }
    } else {
      if (!std::filesystem::exists(name)) throw std::runtime_error(name + ": no such video file");
      capture_[i].open(name);
    }
    if (!capture_[i].isOpened())
      throw std::runtime_error(name + ": cannot open (unplugged camera, or not a video?)");
  }
}

bool FrameSource::next(cv::Mat& left, cv::Mat& right) {
  if (settings_.kind == "images") {
    if (index_ >= files_[0].size()) return false;
    left = read(files_[0][index_]);
    right = read(files_[1][index_]);
    ++index_;
    return true;
  }
  // Grab both, then retrieve both, so the two exposures are as close as the driver allows.
  for (int attempt = 0; attempt < 5; ++attempt) {
    if (capture_[0].grab() && capture_[1].grab() && capture_[0].retrieve(left) &&
        capture_[1].retrieve(right) && !left.empty() && !right.empty()) {
      return true;
    }
    if (!live()) return false;  // a file ended
    spdlog::warn("a camera did not deliver a frame (attempt {} of 5)", attempt + 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  throw std::runtime_error("the cameras stopped delivering frames (unplugged?)");
}

cv::Mat FrameSource::read(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(path + ": cannot read the image");
  return image;
}

void play_frames(FrameSource& source, StereoPublisher& vision, const PlaySettings& settings) {
  using std::chrono::microseconds;
  const int64_t start_utime = sg::now_utime();
  const auto start = std::chrono::steady_clock::now();
  const double rate = settings.rate_hz > 0 ? settings.rate_hz : settings.fps;
  cv::Mat left, right;
  for (int64_t k = 0;
       (settings.max_frames == 0 || k < settings.max_frames) && !sg::shutdown_requested(); ++k) {
    if (settings.rate_hz > 0)
      std::this_thread::sleep_until(start + microseconds(std::llround(k * 1e6 / settings.rate_hz)));
    if (!source.next(left, right)) break;
    const int64_t utime =
        source.live() ? sg::now_utime() : start_utime + std::llround(k * 1e6 / rate);
    vision.process(left, right, k, utime);
  }
  vision.report(0, 0);
}

}  // namespace sg::vision
