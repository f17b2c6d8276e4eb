// sg-viewer: the paper's user interface. Shows both cameras with the ball's centroid, the yellow
// search window, the axes, the 3D position, the predicted trajectory and the frame rate, in a
// window when there is a display, or records the same view to a video file.
//
//   sg-viewer                                   # a window
//   sg-viewer --record session.avi --calibration cams.yaml
//            (also writes session.avi.csv: recorded frame, utime)

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <deque>
#include <fstream>
#include <map>
#include <opencv2/highgui.hpp>
#include <opencv2/videoio.hpp>

#include "common/bus.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "vision/image_message.hpp"
#include "vision/viewer_canvas.hpp"

namespace {

using stereograsp::blob_t;
using stereograsp::image_t;

/// Keeps recent frames and blobs by capture time, and says when a stereo frame is ready to draw.
struct Frames {
  struct Entry {
    std::array<cv::Mat, 2> images;
    std::array<std::optional<blob_t>, 2> blobs;
    std::optional<stereograsp::point3_t> position;
  };
  std::map<int64_t, Entry> by_utime;

  Entry& at(int64_t utime) {
    Entry& e = by_utime[utime];
    while (by_utime.size() > 60) by_utime.erase(by_utime.begin());
    return e;
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The user interface: both cameras with what the vision stage found.", "sg-viewer"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  std::string record, calibration_path;
  double record_fps = 30;
  int64_t max_frames = 0;
  bool no_window = false, wait_for_blobs = true;
  app.add_option("--record", record, "write the view to this video file (MJPG AVI) and FILE.csv");
  app.add_option("--record-fps", record_fps, "frame rate written into the video file");
  app.add_option("--calibration", calibration_path,
                 "calibration file: draw the predicted trajectory");
  app.add_option("--frames", max_frames, "stop after drawing this many frames (0: no limit)");
  app.add_flag("--no-window", no_window, "do not open a window even with a display");
  app.add_flag("!--no-blobs", wait_for_blobs,
               "draw frames as they come, without waiting for blobs");

  return sg::run_program(app, argc, argv, [&] {
    sg::load_common(common);
    std::optional<sg::vision::StereoCalibration> calibration;
    if (!calibration_path.empty()) calibration = sg::vision::read_calibration(calibration_path);
    const bool window = !no_window && std::getenv("DISPLAY") != nullptr;
    if (!window && record.empty())
      throw std::runtime_error(
          "no display (DISPLAY is not set): give --record FILE to write a video");
    sg::install_shutdown_handlers();
    sg::Bus bus(common.lcm_url);

    Frames frames;
    sg::vision::ViewerState state;
    state.calibration = calibration ? &*calibration : nullptr;
    cv::VideoWriter writer;
    std::ofstream index;
    int64_t drawn = 0;
    std::deque<int64_t> recent;  // utimes of drawn frames, for the frame rate
    cv::Mat canvas;

    auto draw = [&](int64_t utime, Frames::Entry& e) {
      state.images = e.images;
      state.blobs = e.blobs;
      state.position = e.position;
      state.utime = utime;
      recent.push_back(utime);
      while (recent.size() > 30) recent.pop_front();
      if (recent.size() > 1)
        state.frame_rate = (recent.size() - 1) * 1e6 / double(recent.back() - recent.front());
      sg::vision::draw_view(state, canvas);
      if (!record.empty()) {
        if (!writer.isOpened()) {
          writer.open(record, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), record_fps,
                      canvas.size());
          if (!writer.isOpened()) throw std::runtime_error(record + ": cannot write the video");
          index.open(record + ".csv");
          index << "video_frame,utime\n";
        }
        writer.write(canvas);
        index << drawn << "," << utime << "\n";
      }
      if (window) {
        cv::imshow("stereograsp", canvas);
        if (cv::waitKey(1) == 27) sg::request_shutdown();
      }
      ++drawn;
      frames.by_utime.erase(frames.by_utime.begin(), frames.by_utime.upper_bound(utime));
    };
    auto maybe_draw = [&](int64_t utime) {
      Frames::Entry& e = frames.at(utime);
      const bool images = !e.images[0].empty() && !e.images[1].empty();
      const bool blobs = e.blobs[0] && e.blobs[1];
      if (images && (blobs || !wait_for_blobs)) draw(utime, e);
    };

    bus.subscribe<image_t>(
        "CAMERA_(LEFT|RIGHT)", [&](const image_t& m, const sg::ReceiveInfo& info) {
          std::string error;
          auto image = sg::vision::decode_image(m, &error);
          if (!image) {
            spdlog::warn("{}: dropped an image: {}", info.channel, error);
            return;
          }
          frames.at(m.utime).images[info.channel == "CAMERA_LEFT" ? 0 : 1] = *image;
          maybe_draw(m.utime);
        });
    bus.subscribe<blob_t>("BLOB_(LEFT|RIGHT)", [&](const blob_t& b, const sg::ReceiveInfo& info) {
      frames.at(b.utime).blobs[info.channel == "BLOB_LEFT" ? 0 : 1] = b;
      maybe_draw(b.utime);
    });
    bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION", [&](const auto& p, const auto&) {
      frames.at(p.utime).position = p;  // drawn with its own frame
    });
    bus.subscribe<stereograsp::trajectory_t>(
        "OBJECT_TRAJECTORY", [&](const auto& t, const auto&) { state.trajectory = t; });
    bus.subscribe<stereograsp::grasp_status_t>(
        "GRASP_STATUS", [&](const auto& g, const auto&) { state.grasp = g; });
    spdlog::info("waiting for CAMERA_LEFT/RIGHT{}", wait_for_blobs ? " and BLOB_LEFT/RIGHT" : "");
    bus.spin([&] { return max_frames == 0 || drawn < max_frames; });
    std::printf("drew %lld frames%s%s\n", static_cast<long long>(drawn),
                record.empty() ? "" : " into ", record.c_str());
    return 0;
  });
}
