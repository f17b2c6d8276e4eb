// sg-vision: finds the red ball in both cameras (sections 5.1-5.3) and, with a calibration,
// places it in 3D (section 5.4). Publishes BLOB_LEFT, BLOB_RIGHT for every stereo frame and
// OBJECT_POSITION when --calibration is given.
//
//   sg-vision --calibration cams.yaml                      # frames from CAMERA_LEFT/RIGHT (sim,
//   log) sg-vision --source video --left l.avi --right r.avi    # two video files sg-vision
//   --source images --left dirL --right dirR     # two folders of images, by name sg-vision
//   --source v4l2 --left /dev/video0 --right /dev/video1 --publish-images sg-vision learn-color
//   frame.png --roi 300,200,20,20    # colour ranges for config

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <thread>

#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/latency_record.hpp"
#include "common/program.hpp"
#include "common/realtime.hpp"
#include "common/shutdown.hpp"
#include "vision/blob_tracker.hpp"
#include "vision/calibration_file.hpp"
#include "vision/decode_worker.hpp"
#include "vision/frame_cadence.hpp"
#include "vision/frame_decoder.hpp"
#include "vision/image_folder.hpp"
#include "vision/image_message.hpp"
#include "vision/stereo_pairer.hpp"
#include "vision/stereo_step.hpp"
#include "vision/vision_config.hpp"

namespace {

using namespace std::chrono;
namespace fs = std::filesystem;
using stereograsp::blob_t;
using stereograsp::image_t;
using stereograsp::point3_t;

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

/// Runs the stereo step on each pair and publishes what it found.
class StereoVision {
 public:
  StereoVision(sg::Bus& bus, const sg::vision::VisionSettings& settings, cv::Size size,
               std::optional<sg::vision::StereoCalibration> calibration, bool publish_images)
      : bus_(bus),
        step_(settings.tracker, size, std::move(calibration), settings.match),
        publish_images_(publish_images) {}

  /// When a pair's OBJECT_POSITION went out (sg::now_utime(); 0 when there was none): handed to
  /// the bus (sg::Bus::last_handed_utime()), and the bus's publish() returned.
  struct Published {
    int64_t handed = 0, returned = 0;
  };

  /// Tracks a pair and publishes OBJECT_POSITION (when seen), then BLOB_LEFT and BLOB_RIGHT.
  Published process(const cv::Mat& left, const cv::Mat& right, int64_t frame_number,
                    int64_t utime) {
    if (publish_images_) {
      const cv::Mat* images[2] = {&left, &right};
      for (int i = 0; i < 2; ++i)
        bus_.publish(i == 0 ? "CAMERA_LEFT" : "CAMERA_RIGHT",
                     sg::vision::encode_image(*images[i], static_cast<int8_t>(i), frame_number,
                                              utime, true));
    }
    const sg::vision::StereoOutput out = step_.process(left, right, frame_number, utime);
    // The position first, so that a viewer drawing on the blobs has the frame's position too.
    Published published;
    if (out.position) {
      bus_.publish("OBJECT_POSITION", *out.position);
      published = {bus_.last_handed_utime(), sg::now_utime()};
    }
    bus_.publish("BLOB_LEFT", out.blob[0]);
    bus_.publish("BLOB_RIGHT", out.blob[1]);
    return published;
  }

  cv::Rect next_window(size_t camera, cv::Size frame) const {
    return step_.next_window(camera, frame);
  }

  void report(uint64_t unmatched, uint64_t bad_images) const {
    const sg::vision::StereoCounts& c = step_.counts();
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

 private:
  sg::Bus& bus_;
  sg::vision::StereoStep step_;
  bool publish_images_;
};

/// CPU time of the whole process, every thread's, in seconds.
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// Stereo pairs from CAMERA_LEFT and CAMERA_RIGHT: paired as messages, each decoded where its
/// tracker will look (frame_decoder.hpp); the pair's first image on its camera's DecodeWorker as
/// it arrives, the second in line when it completes the pair, so the two decode at once. Times
/// each pair from the second image's arrival to OBJECT_POSITION published.
class BusFrames {
 public:
  using Message = std::shared_ptr<const image_t>;

  BusFrames(StereoVision& vision, const Options& o, sg::vision::FrameDecoder::Mode mode,
            std::chrono::microseconds busy_wait)
      : vision_(vision),
        pairer_(std::llround(o.pair_tolerance_ms * 1000)),
        workers_{sg::vision::DecodeWorker(mode), sg::vision::DecodeWorker(mode)},
        cadence_(busy_wait),
        busy_wait_(busy_wait),
        started_(steady_clock::now()),
        started_cpu_s_(process_cpu_seconds()) {}

  void on_image(const image_t& m, const sg::ReceiveInfo& info) {
    const int64_t start = sg::now_utime();
    const auto arrival = sg::vision::FrameCadence::Clock::now();
    const size_t side = info.channel == "CAMERA_LEFT" ? 0 : 1;
    if (const std::string e = sg::vision::image_message_error(m); !e.empty()) return drop(info, e);
    auto message = std::make_shared<const image_t>(m);
    auto pair = pairer_.add(static_cast<int>(side), m.utime, message);
    if (!pair) {
      first_arrival_ = arrival;
      awake_ += polling_;
      workers_[side].post(std::move(message), window(side, m));
      // The pair's second image is decoded here: the other worker has nothing to take until the
      // next pair, and polling it would share the first image's core with its decode.
      workers_[1 - side].stay_awake_until({});
      first_waiting_ = true;
      return;
    }
    first_waiting_ = false;
    cadence_.arrived(first_arrival_);  // awake for the next pair's first image
    const Message messages[2] = {pair->first, pair->second};
    const cv::Mat* frames[2];
    std::string error;
    frames[side] = workers_[side].decode(messages[side], window(side, m), &error);
    if (!frames[side]) return drop(info, error);
    if (!(frames[1 - side] = collect(1 - side, messages[1 - side], &error)))
      return drop(info, error);
    const auto published =
        vision_.process(*frames[0], *frames[1], pair->first->frame_number, pair->first->utime);
    if (published.handed != 0) {  // the stopwatch stops at OBJECT_POSITION, not the blobs after
      pair_to_position_.add(published.handed - info.recv_utime);
      delivery_.add(start - info.recv_utime);
      handling_.add(published.handed - start);
      pair_to_return_.add(published.returned - info.recv_utime);
    }
    ++pairs_;
  }

  int64_t pairs() const { return pairs_; }
  /// How long to sleep waiting for a message now: none around the next pair's due time.
  /// While a pair is due, and until its first image comes, the decode workers stay awake too, so
  /// that the first image's is already running on the other core when it comes
  /// (decode_worker.hpp).
  std::chrono::microseconds wait() {
    const auto now = sg::vision::FrameCadence::Clock::now();
    const std::chrono::microseconds sleep =
        cadence_.sleep_before_next(now, std::chrono::milliseconds(100));
    polling_ = sleep.count() == 0 && busy_wait_.count() > 0;
    if (!polling_) return sleep;
    if (!first_waiting_)
      for (auto& worker : workers_) worker.stay_awake_until(now + 2 * busy_wait_);
    return busy_wait_;  // the workers poll; this thread sleeps until a frame, or renews that
  }
  void set_read_directly(bool direct) { read_directly_ = direct; }
  void report(uint64_t bus_errors) const {
    vision_.report(pairer_.unmatched(), bad_ + bus_errors);
    std::printf("second image received -> OBJECT_POSITION handed to the bus: %s (decode: %s)\n",
                pair_to_position_.summary().c_str(),
                workers_[0].decoder().mode() == sg::vision::FrameDecoder::Mode::kRegion ? "region"
                                                                                        : "full");
    std::printf("  of which the delivery to the image's handler: %s\n",
                delivery_.summary().c_str());
    std::printf(
        "  (the camera channels read %s; the first image of a pair decoded by its worker "
        "%llu times, in line %llu times; %llu first images found sg-vision awake)\n",
        read_directly_ ? "directly, on sg-vision's own socket on the bus's group"
                       : "through LCM's subscription",
        static_cast<unsigned long long>(workers_[0].by_worker() + workers_[1].by_worker()),
        static_cast<unsigned long long>(workers_[0].by_caller() + workers_[1].by_caller()),
        static_cast<unsigned long long>(awake_));
    std::printf("  of which in the image's handler (decode, track, publish): %s\n",
                handling_.summary().c_str());
    std::printf(
        "second image received -> the bus's publish() of OBJECT_POSITION returned (its delivery "
        "to this host's subscribers included): %s\n",
        pair_to_return_.summary().c_str());
    const double cpu_s = process_cpu_seconds() - started_cpu_s_;
    const double wall_s = duration<double>(steady_clock::now() - started_).count();
    std::printf("CPU time: %.2f s in %.1f s (%.1f %% of one core), %.2f ms a pair\n", cpu_s, wall_s,
                100 * cpu_s / std::max(wall_s, 1e-9),
                pairs_ ? 1000 * cpu_s / static_cast<double>(pairs_) : 0.0);
  }

 private:
  void drop(const sg::ReceiveInfo& info, const std::string& error) {
    if (++bad_ <= 10 || bad_ % 1000 == 0)
      spdlog::warn("{}: dropped an image: {} ({} so far)", info.channel, error, bad_);
  }

  cv::Rect window(size_t side, const image_t& m) const {
    return vision_.next_window(side, cv::Size(m.width, m.height));
  }

  /// The waiting image's frame from its worker; decoded again here when the worker's is another
  /// message's, or when the tracker now looks beyond what was decoded (a pair processed since),
  /// but never again when the message did not decode.
  const cv::Mat* collect(size_t side, const Message& message, std::string* error) {
    sg::vision::DecodeWorker& worker = workers_[side];
    const cv::Mat* frame = worker.collect(error);
    const cv::Size size(message->width, message->height);
    const cv::Rect want = window(side, *message);
    const cv::Rect need = want.empty() ? cv::Rect({}, size) : want;
    if (worker.message() == message && (!frame || (need & worker.decoder().decoded()) == need))
      return frame;  // decoded where the tracker looks, or not decodable (`error` says why)
    return worker.decode(message, want, error);
  }

  StereoVision& vision_;
  sg::vision::StereoPairer<Message> pairer_;
  sg::vision::DecodeWorker workers_[2];
  sg::vision::FrameCadence cadence_;
  std::chrono::microseconds busy_wait_;  // vision.busy_wait_ms as used (busy_wait())
  sg::vision::FrameCadence::Clock::time_point first_arrival_{};
  bool polling_ = false;        // a pair is due: the workers poll (busy_wait_ms)
  bool first_waiting_ = false;  // a pair's first image is posted, its second not yet come
  uint64_t awake_ = 0;          // pairs whose first image found it so
  sg::LatencyRecord pair_to_position_, delivery_, handling_, pair_to_return_;
  uint64_t bad_ = 0;
  int64_t pairs_ = 0;
  bool read_directly_ = false;
  steady_clock::time_point started_;
  double started_cpu_s_;  // the process's CPU time (every thread's) then
};

/// vision.busy_wait_ms as the thread may use it: not at SCHED_FIFO, where a thread that polls
/// keeps the kernel's own threads (ksoftirqd, which may be delivering the frame) off its core.
std::chrono::microseconds busy_wait(const sg::vision::VisionSettings& settings) {
  if (settings.realtime_priority > 0 && settings.busy_wait_ms > 0) {
    spdlog::info("vision.busy_wait_ms is not used at SCHED_FIFO: sleeping until frames come");
    return std::chrono::microseconds(0);
  }
  return std::chrono::microseconds(std::llround(settings.busy_wait_ms * 1000));
}

int run_lcm(sg::Bus& bus, StereoVision& vision, const Options& o,
            const sg::vision::VisionSettings& settings) {
  BusFrames frames(vision, o,
                   settings.decode == "full" ? sg::vision::FrameDecoder::Mode::kFull
                                             : sg::vision::FrameDecoder::Mode::kRegion,
                   busy_wait(settings));
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

/// Frames from two video files, two folders of images, or two V4L2 cameras.
class FrameSource {
 public:
  explicit FrameSource(const Options& o) : o_(o) {
    if (o.left.empty() || o.right.empty())
      throw std::runtime_error("--left and --right are required for --source " + o.source);
    if (o.source == "images") {
      files_[0] = sg::vision::list_images(o.left);
      files_[1] = sg::vision::list_images(o.right);
      if (files_[0].size() != files_[1].size())
        throw std::runtime_error("--left has " + std::to_string(files_[0].size()) +
                                 " images but --right has " + std::to_string(files_[1].size()));
      return;
    }
    for (int i = 0; i < 2; ++i) {
      const std::string& name = i == 0 ? o.left : o.right;
      if (o.source == "v4l2") {
        capture_[i].open(name, cv::CAP_V4L2);
        if (capture_[i].isOpened()) {
          capture_[i].set(cv::CAP_PROP_FRAME_WIDTH, o.width);
          capture_[i].set(cv::CAP_PROP_FRAME_HEIGHT, o.height);
          capture_[i].set(cv::CAP_PROP_FPS, o.fps);
        }
      } else {
        if (!fs::exists(name)) throw std::runtime_error(name + ": no such video file");
        capture_[i].open(name);
      }
      if (!capture_[i].isOpened())
        throw std::runtime_error(name + ": cannot open (unplugged camera, or not a video?)");
    }
  }

  /// The next pair; false at the end (or after a camera stops answering).
  bool next(cv::Mat& left, cv::Mat& right) {
    if (o_.source == "images") {
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
      if (o_.source != "v4l2") return false;  // a file ended
      spdlog::warn("a camera did not deliver a frame (attempt {} of 5)", attempt + 1);
      std::this_thread::sleep_for(milliseconds(100));
    }
    throw std::runtime_error("the cameras stopped delivering frames (unplugged?)");
  }

  bool live() const { return o_.source == "v4l2"; }

 private:
  static cv::Mat read(const std::string& path) {
    cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
    if (image.empty()) throw std::runtime_error(path + ": cannot read the image");
    return image;
  }

  Options o_;
  cv::VideoCapture capture_[2];
  std::vector<std::string> files_[2];
  size_t index_ = 0;
};

int run_frames(StereoVision& vision, const Options& o) {
  FrameSource source(o);
  const int64_t start_utime = sg::now_utime();
  const auto start = steady_clock::now();
  const double rate = o.rate_hz > 0 ? o.rate_hz : o.fps;
  cv::Mat left, right;
  int64_t k = 0;
  for (; (o.max_frames == 0 || k < o.max_frames) && !sg::shutdown_requested(); ++k) {
    if (o.rate_hz > 0)
      std::this_thread::sleep_until(start + microseconds(std::llround(k * 1e6 / o.rate_hz)));
    if (!source.next(left, right)) break;
    // Capture time: the clock for live cameras, the frame's place in the recording for files.
    const int64_t utime =
        source.live() ? sg::now_utime() : start_utime + std::llround(k * 1e6 / rate);
    vision.process(left, right, k, utime);
  }
  vision.report(0, 0);
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
    sg::Bus bus(common.lcm_url);
    const cv::Size size = calibration
                              ? cv::Size(calibration->left.width(), calibration->left.height())
                              : cv::Size(o.width, o.height);
    StereoVision vision(bus, settings, size, calibration, o.publish_images);
    return o.source == "lcm" ? run_lcm(bus, vision, o, settings) : run_frames(vision, o);
  });
}
