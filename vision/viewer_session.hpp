#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <fstream>
#include <functional>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>

#include "vision/viewer_canvas.hpp"

namespace sg::vision {

/// sg-viewer's logic without the bus: it pairs both cameras' frames with their blobs by capture
/// time, draws a stereo frame once it is complete (draw_view), records the view to a video file
/// with an index (video frame, utime), and hands each drawn canvas to `show` (a window).
class ViewerSession {
 public:
  struct Options {
    std::string record;          ///< a video file (MJPG AVI) and FILE.csv; "" = none
    double record_fps = 30;      ///< written into the video file
    bool wait_for_blobs = true;  ///< draw a frame only once both blobs are in
  };
  using Show = std::function<void(const cv::Mat& canvas)>;

  /// `calibration` (may be null) must outlive the session.
  ViewerSession(Options options, const StereoCalibration* calibration, Show show = {});

  void on_image(int camera, int64_t utime, const cv::Mat& image);  ///< camera 0 left, 1 right
  void on_blob(int camera, const stereograsp::blob_t& blob);
  void on_position(const stereograsp::point3_t& position);  ///< drawn with its own frame
  void on_trajectory(const stereograsp::trajectory_t& trajectory) {
    state_.trajectory = trajectory;
  }
  void on_grasp(const stereograsp::grasp_status_t& grasp) { state_.grasp = grasp; }

  int64_t drawn() const { return drawn_; }

 private:
  struct Entry {
    std::array<cv::Mat, 2> images;
    std::array<std::optional<stereograsp::blob_t>, 2> blobs;
    std::optional<stereograsp::point3_t> position;
  };
  Entry& at(int64_t utime);  ///< keeps the 60 newest capture times
  void maybe_draw(int64_t utime);
  void draw(int64_t utime, Entry& entry);
  void record(const cv::Mat& canvas, int64_t utime);

  Options options_;
  Show show_;
  ViewerState state_;
  std::map<int64_t, Entry> by_utime_;
  std::deque<int64_t> recent_;  ///< utimes of drawn frames, for the frame rate
  cv::Mat canvas_;
  cv::VideoWriter writer_;
  std::ofstream index_;
  int64_t drawn_ = 0;
};

}  // namespace sg::vision
