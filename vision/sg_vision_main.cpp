// sg-vision: finds the red ball in both cameras (sections 5.1-5.3) and, with a calibration,
// places it in 3D (section 5.4). Publishes BLOB_LEFT, BLOB_RIGHT for every stereo frame and
// OBJECT_POSITION when --calibration is given. Wiring only: the frames come from BusFrames
// (vision/bus_frames.hpp) or a FrameSource (vision/frame_source.hpp), and go out through a
// StereoPublisher (vision/stereo_publisher.hpp).
//
//   sg-vision --calibration cams.yaml                         # CAMERA_LEFT/RIGHT (sim, log)
//   sg-vision --source video --left l.avi --right r.avi       # two video files
//   sg-vision --source images --left dirL --right dirR        # two folders of images, by name
//   sg-vision --source v4l2 --left /dev/video0 --right /dev/video1 --publish-images
//   sg-vision learn-color frame.png --roi 300,200,20,20       # colour ranges for config

#include <spdlog/spdlog.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/program.hpp"
#include "common/realtime.hpp"
#include "common/shutdown.hpp"
#include "vision/bus_frames.hpp"
#include "vision/calibration_file.hpp"
#include "vision/color_detector.hpp"
#include "vision/frame_source.hpp"
#include "vision/stereo_publisher.hpp"
#include "vision/vision_config.hpp"

namespace {

using sg::vision::BusFrames;
using sg::vision::FrameDecoder;
using sg::vision::StereoPublisher;
using stereograsp::image_t;

struct Options {
  std::string source = "lcm";
  std::string left, right;
  std::string calibration;
  double rate_hz = 0;  // files: pace to this rate (0: as fast as possible)
  int width = 640, height = 480;
  double fps = 30;
  bool publish_images = false;
  int64_t max_frames = 0;
  double pair_tolerance_ms = 5.0;
};

/// Frames from CAMERA_LEFT and CAMERA_RIGHT until --frames pairs, or a shutdown signal.
int run_lcm(sg::Bus& bus, StereoPublisher& vision, const Options& o,
            const sg::vision::VisionSettings& settings) {
  BusFrames frames(vision, {.pair_tolerance_us = std::llround(o.pair_tolerance_ms * 1000),
                            .mode = settings.decode == "full" ? FrameDecoder::Mode::kFull
                                                              : FrameDecoder::Mode::kRegion,
                            .busy_wait = sg::vision::busy_wait_as_used(settings)});
  auto on_image = [&](const image_t& m, const sg::ReceiveInfo& info) { frames.on_image(m, info); };
  bool direct = false;
  if (settings.camera_read == "direct") {  // this thread, not LCM's receive thread (issue 19)
    direct = bus.subscribe_direct<image_t>("CAMERA_LEFT", on_image, sg::kQueueFrames);
    direct = bus.subscribe_direct<image_t>("CAMERA_RIGHT", on_image, sg::kQueueFrames) && direct;
  } else {
    bus.subscribe<image_t>("CAMERA_LEFT", on_image, sg::kQueueFrames);
    bus.subscribe<image_t>("CAMERA_RIGHT", on_image, sg::kQueueFrames);
  }
  frames.set_read_directly(direct);
  bus.announce("sg-vision");  // after subscribing: the first PROCESS_STATUS says it listens
  spdlog::info("waiting for CAMERA_LEFT and CAMERA_RIGHT");
  bus.spin([&] { return o.max_frames == 0 || frames.pairs() < o.max_frames; },
           [&] { return frames.wait(); });
  frames.report(bus.decode_errors());
  return 0;
}

/// Frames from two video files, two folders of images or two V4L2 cameras.
int run_frames(StereoPublisher& vision, const Options& o) {
  sg::vision::FrameSource source({.kind = o.source,
                                  .left = o.left,
                                  .right = o.right,
                                  .width = o.width,
                                  .height = o.height,
                                  .fps = o.fps});
  sg::vision::play_frames(source, vision,
                          {.rate_hz = o.rate_hz, .fps = o.fps, .max_frames = o.max_frames});
  return 0;
}

int learn_color(const std::string& image_path, const std::string& roi_text) {
  const cv::Mat image = cv::imread(image_path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(image_path + ": cannot read the image");
  int x, y, w, h;
  char c1, c2, c3;
  std::istringstream in(roi_text);
  if (!(in >> x >> c1 >> y >> c2 >> w >> c3 >> h) || c1 != ',' || c2 != ',' || c3 != ',' ||
      w <= 0 || h <= 0)
    throw std::runtime_error("--roi '" + roi_text + "': expected x,y,w,h in pixels");
  const auto t = sg::vision::ColorThresholds::learn(image, cv::Rect(x, y, w, h));
  std::printf("# learned by: sg-vision learn-color %s --roi %s\nvision:\n", image_path.c_str(),
              roi_text.c_str());
  std::printf("  r_range: [%.3f, %.3f]\n  g_range: [%.3f, %.3f]\n  b_range: [%.3f, %.3f]\n",
              t.r_min, t.r_max, t.g_min, t.g_max, t.b_min, t.b_max);
  std::printf("  min_intensity: %d\n", t.min_intensity);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Finds the red ball in both cameras and places it in 3D.", "sg-vision"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  const auto keys = sg::declared_keys(sg::vision::read_vision_settings);
  common.flags.add(app, "--decode", "vision.decode", keys);
  common.flags.add(app, "--camera-read", "vision.camera_read", keys);
  common.flags.add(app, "--realtime-priority", "vision.realtime_priority", keys);
  common.flags.add(app, "--busy-wait-ms", "vision.busy_wait_ms", keys);
  Options o;
  app.add_option("--source", o.source, "lcm (CAMERA_LEFT/RIGHT), video, images or v4l2")
      ->check(CLI::IsMember({"lcm", "video", "images", "v4l2"}));
  app.add_option("--left", o.left, "left video file, image folder or V4L2 device");
  app.add_option("--right", o.right, "right video file, image folder or V4L2 device");
  app.add_option("--calibration", o.calibration,
                 "stereo calibration file: also publish OBJECT_POSITION");
  app.add_option("--rate", o.rate_hz,
                 "files: frames per second to pace to (default: as fast as possible)");
  app.add_option("--fps", o.fps,
                 "files: frame rate of the recording (capture times); v4l2: rate to ask");
  app.add_option("--width", o.width, "v4l2: image width");
  app.add_option("--height", o.height, "v4l2: image height");
  app.add_flag("--publish-images", o.publish_images,
               "republish captured frames as JPEG CAMERA_LEFT/RIGHT");
  app.add_option("--frames", o.max_frames, "stop after this many stereo frames (0: no limit)");
  app.add_option("--pair-tolerance-ms", o.pair_tolerance_ms,
                 "lcm: largest utime difference within a pair");
  std::string learn_image, learn_roi;
  CLI::App* learn =
      app.add_subcommand("learn-color", "Print colour ranges learned from a sample of the ball");
  learn->add_option("IMAGE", learn_image, "an image with the ball")->required();
  learn->add_option("--roi", learn_roi, "x,y,w,h of a region inside the ball")->required();

  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    if (*learn) return learn_color(learn_image, learn_roi);
    const sg::vision::VisionSettings settings = sg::vision::read_vision_settings(config);
    if (o.calibration.empty()) o.calibration = settings.calibration;
    std::optional<sg::vision::StereoCalibration> calibration;
    if (!o.calibration.empty()) calibration = sg::vision::read_calibration(o.calibration);
    if (o.publish_images && o.source == "lcm")
      throw std::runtime_error(
          "--publish-images republishes frames from cameras or files, not from the bus");
    sg::install_shutdown_handlers();
    // Before the bus: LCM's receive thread inherits the policy.
    if (const std::string e = sg::enter_realtime(settings.realtime_priority); !e.empty())
      spdlog::warn("{}", e);
    return sg::auth::with_lab_access(app.get_name(), key_options, [&](auto& lab) {
      sg::Bus bus(common.lcm_url);
      lab.guard(bus);  // believes CAMERA_* only from the cameras
      const cv::Size size = calibration
                                ? cv::Size(calibration->left.width(), calibration->left.height())
                                : cv::Size(o.width, o.height);
      StereoPublisher vision(bus, settings, size, calibration, o.publish_images);
      return o.source == "lcm" ? run_lcm(bus, vision, o, settings) : run_frames(vision, o);
    });
  });
}
