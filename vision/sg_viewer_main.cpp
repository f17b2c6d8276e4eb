// sg-viewer: the paper's user interface. Shows both cameras with the ball's centroid, the yellow
// search window, the axes, the 3D position, the predicted trajectory and the frame rate, in a
// window when there is a display, or records the same view to a video file.
//
//   sg-viewer                                   # a window
//   sg-viewer --record session.avi --calibration cams.yaml
//            (also writes session.avi.csv: recorded frame, utime)

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <opencv2/highgui.hpp>
#include <opencv2/videoio.hpp>

#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "vision/image_message.hpp"
#include "vision/viewer_session.hpp"

namespace {

using stereograsp::blob_t;
using stereograsp::image_t;

/// Feeds the session from the bus until --frames are drawn or shutdown.
int run(const std::string& url, sg::vision::ViewerSession& session, int64_t max_frames,
        bool wait_for_blobs, const sg::auth::KeyOptions& key_options) {
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  sg::auth::guard_if_key(bus, "sg-viewer", key_options);  // it only looks: a key is optional
  bus.announce("sg-viewer");
  bus.subscribe<image_t>(
      "CAMERA_(LEFT|RIGHT)",
      [&](const image_t& m, const sg::ReceiveInfo& info) {
        std::string error;
        auto image = sg::vision::decode_image(m, &error);
        if (!image) {
          spdlog::warn("{}: dropped an image: {}", info.channel, error);
          return;
        }
        session.on_image(info.channel == "CAMERA_LEFT" ? 0 : 1, m.utime, *image);
      },
      sg::kQueueFrames);
  bus.subscribe<blob_t>("BLOB_(LEFT|RIGHT)", [&](const blob_t& b, const sg::ReceiveInfo& info) {
    session.on_blob(info.channel == "BLOB_LEFT" ? 0 : 1, b);
  });
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION",
                                       [&](const auto& p, const auto&) { session.on_position(p); });
  bus.subscribe<stereograsp::trajectory_t>(
      "OBJECT_TRAJECTORY", [&](const auto& t, const auto&) { session.on_trajectory(t); });
  bus.subscribe<stereograsp::grasp_status_t>(
      "GRASP_STATUS", [&](const auto& g, const auto&) { session.on_grasp(g); });
  spdlog::info("waiting for CAMERA_LEFT/RIGHT{}", wait_for_blobs ? " and BLOB_LEFT/RIGHT" : "");
  bus.spin([&] { return max_frames == 0 || session.drawn() < max_frames; });
  return 0;
}

/// A window's show function, or none without a display.
sg::vision::ViewerSession::Show window_or_none(bool window) {
  if (!window) return {};
  return [](const cv::Mat& canvas) {
    cv::imshow("stereograsp", canvas);
    if (cv::waitKey(1) == 27) sg::request_shutdown();
  };
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The user interface: both cameras with what the vision stage found.", "sg-viewer"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  sg::vision::ViewerSession::Options o;
  std::string calibration_path;
  int64_t max_frames = 0;
  bool no_window = false;
  app.add_option("--record", o.record, "write the view to this video file (MJPG AVI) and FILE.csv");
  app.add_option("--record-fps", o.record_fps, "frame rate written into the video file")
      ->capture_default_str();
  app.add_option("--calibration", calibration_path,
                 "calibration file: draw the predicted trajectory");
  app.add_option("--frames", max_frames, "stop after drawing this many frames (0: no limit)");
  app.add_flag("--no-window", no_window, "do not open a window even with a display");
  app.add_flag("!--no-blobs", o.wait_for_blobs,
               "draw frames as they come, without waiting for blobs");

  return sg::run_program(app, argc, argv, [&] {
    sg::load_common(common);
    std::optional<sg::vision::StereoCalibration> calibration;
    if (!calibration_path.empty()) calibration = sg::vision::read_calibration(calibration_path);
    const bool window = !no_window && std::getenv("DISPLAY") != nullptr;
    if (!window && o.record.empty())
      throw std::runtime_error(
          "no display (DISPLAY is not set): give --record FILE to write a video");
    sg::vision::ViewerSession session(o, calibration ? &*calibration : nullptr,
                                      window_or_none(window));
    run(common.lcm_url, session, max_frames, o.wait_for_blobs, key_options);
    std::printf("drew %lld frames%s%s\n", static_cast<long long>(session.drawn()),
                o.record.empty() ? "" : " into ", o.record.c_str());
    return 0;
  });
}
