// The frame path through the real processes (issue 19): stereo frames published on CAMERA_LEFT and
// CAMERA_RIGHT, stamped with the time they are published, go over LCM (UDP multicast, this
// host) to sg-vision and sg-predictor, started as processes; this program times OBJECT_POSITION
// and OBJECT_TRAJECTORY as they arrive (their receive time less the frames' utime) and reads
// sg-vision's own figure, second image received -> OBJECT_POSITION handed to the bus, from its
// summary. Five runs: JPEG with only the search windows decoded (vision.decode: region, the
// default), the camera channels read on sg-vision's own socket (vision.camera_read: direct, the
// default) and its decode workers awake when a pair is due (vision.busy_wait_ms: 1, the default),
// every message vouched for (the frames as sg-camera-sim's: docs/security.md); the same with
// every program run --insecure-no-key and nothing vouched for (the baseline for vouching);
// the same read through LCM's subscription (the baseline for the direct read); the same with
// the workers asleep until a frame comes (busy_wait_ms 0); JPEG decoded whole (the baseline for
// the windows); raw BGR8. The frames are the simulated lab's, rendered and
// encoded before the run (sg-camera-sim's encoder), so rendering is not timed; they are paced as
// sg-camera-sim paces them.
//
//   scripts/multicast.sh run build/bin/frame_path_latency [--pairs 300] [--rate 20]
//
// Goals (issue 19): sg-vision's own added latency p99 <= 1.5 ms (JPEG, windows decoded).

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "auth/data_auth.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/latency_record.hpp"
#include "common/message_types.hpp"
#include "sim/camera_simulator.hpp"
#include "vision/calibration_file.hpp"
#include "vision/image_message.hpp"

extern char** environ;

namespace {

using namespace std::chrono_literals;
using stereograsp::image_t;

/// A product program as a child process, its standard output to a file; SIGINT when it goes.
class Program {
 public:
  Program(const std::string& name, std::vector<std::string> args, const std::string& out)
      : out_(out) {
    const std::string bin = std::string(SG_BIN_DIR) + "/" + name;
    args.insert(args.begin(), bin);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    posix_spawn_file_actions_addopen(&files, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = posix_spawn(&pid_, bin.c_str(), &files, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&files);
    if (e != 0) throw std::runtime_error("cannot start " + bin);
  }
  ~Program() { stop(); }
  /// SIGINT, then waits; returns its standard output.
  std::string stop() {
    if (pid_ > 0) {
      kill(pid_, SIGINT);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
    std::ifstream f(out_);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }

 private:
  pid_t pid_ = -1;
  std::string out_;
};

struct Frames {
  std::vector<std::array<image_t, 2>> jpeg, raw;
};

/// 60 frames of the simulated lab, JPEG and raw; the cameras written as the calibration.
Frames render(const std::string& calibration) {
  const sg::sim::SimParams params;
  sg::sim::CameraSimulator sim(params);
  sg::vision::StereoCalibration c;
  c.left = sim.camera(0), c.right = sim.camera(1), c.source = "frame_path_latency";
  sg::vision::write_calibration(calibration, c);
  Frames f;
  sg::sim::StereoFrame frame;
  for (int64_t n = 0; n < 60; ++n) {
    sim.render(n, {}, frame);
    std::array<image_t, 2> j, r;
    for (size_t i = 0; i < 2; ++i) {
      j[i] = sg::vision::encode_image(frame.image[i], static_cast<int8_t>(i), n, 0, true);
      r[i] = sg::vision::encode_image(frame.image[i], static_cast<int8_t>(i), n, 0, false);
    }
    f.jpeg.push_back(j), f.raw.push_back(r);
  }
  return f;
}

struct Run {
  std::string name;
  sg::LatencyRecord position, trajectory;
  std::string vision_own;       ///< sg-vision's summary line
  std::string vision_returned;  ///< ... to the bus's publish() returning
  std::string vision_delivery;  ///< ... the part of it before the image's handler (LCM)
  std::string vision_handler;   ///< ... and the part of it in the image's handler
  std::string worker;           ///< who decoded the pairs' first images
  std::string vision_cpu;       ///< sg-vision's CPU time over the run
};

/// Waits until both processes announce themselves on PROCESS_STATUS.
bool wait_ready(sg::Bus& bus, bool& vision, bool& predictor) {
  const auto end = std::chrono::steady_clock::now() + 20s;
  while (!(vision && predictor) && std::chrono::steady_clock::now() < end) bus.handle(50ms);
  return vision && predictor;
}

/// How the runs go: the bus, the frames' rate and count, sg-vision's real-time priority.
struct RunSettings {
  std::string url, dir;
  std::string key;  ///< the lab key file the programs and the frames are vouched with
  int pairs = 300;
  double rate = 20;
  int realtime_priority = 0;
};

/// One run: the two programs, `pairs` frames at `rate` Hz, what arrived.
/// How sg-vision runs: vision.decode, vision.camera_read, vision.busy_wait_ms ("": the default).
struct VisionVariant {
  std::string decode = "region", camera_read = "direct", busy_wait_ms;
  bool vouched = true;  ///< false: every program with --insecure-no-key, frames unvouched
};

void run(const RunSettings& rs, const std::vector<std::array<image_t, 2>>& frames,
         const VisionVariant& variant, Run& out) {
  const std::string &url = rs.url, &dir = rs.dir;
  const int pairs = rs.pairs;
  const double rate = rs.rate;
  sg::Bus bus(url);
  if (variant.vouched)  // the frames come as sg-camera-sim's
    bus.set_guard(std::make_shared<sg::auth::VouchingPublisher>(
        sg::auth::credentials_from_lab_key(sg::auth::LabKey::load(rs.key), "sg-camera-sim")));
  const std::vector<std::string> key = variant.vouched
                                           ? std::vector<std::string>{"--key", rs.key}
                                           : std::vector<std::string>{"--insecure-no-key"};
  bool vision_up = false, predictor_up = false;
  bus.subscribe<stereograsp::process_status_t>("PROCESS_STATUS", [&](const auto& m, const auto&) {
    vision_up |= m.process == "sg-vision", predictor_up |= m.process == "sg-predictor";
  });
  bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION", [&](const auto& m, const auto& info) {
    out.position.add(info.recv_utime - m.utime);
  });
  bus.subscribe<stereograsp::trajectory_t>("OBJECT_TRAJECTORY",
                                           [&](const auto& m, const auto& info) {
                                             out.trajectory.add(info.recv_utime - m.source_utime);
                                           });
  std::vector<std::string> vision_args = {"--calibration",
                                          dir + "/cams.yaml",
                                          "--decode",
                                          variant.decode,
                                          "--camera-read",
                                          variant.camera_read,
                                          "--lcm-url",
                                          url,
                                          "--log-level",
                                          "warn",
                                          "--realtime-priority",
                                          std::to_string(rs.realtime_priority)};
  if (!variant.busy_wait_ms.empty())
    vision_args.insert(vision_args.end(), {"--busy-wait-ms", variant.busy_wait_ms});
  vision_args.insert(vision_args.end(), key.begin(), key.end());
  std::vector<std::string> predictor_args = {"--config", dir + "/predictor.yaml", "--lcm-url",
                                             url,        "--log-level",           "error"};
  predictor_args.insert(predictor_args.end(), key.begin(), key.end());
  Program vision("sg-vision", vision_args, dir + "/vision.out");
  Program predictor("sg-predictor", predictor_args, dir + "/predictor.out");
  if (!wait_ready(bus, vision_up, predictor_up))
    throw std::runtime_error("the programs did not start");
  const auto period = std::chrono::duration<double>(1.0 / rate);
  auto next = std::chrono::steady_clock::now();
  for (int k = 0; k < pairs; ++k) {
    const size_t n = frames.size(), at = static_cast<size_t>(k) % (2 * n - 2);
    std::array<image_t, 2> pair = frames[at < n ? at : 2 * n - 2 - at];  // forwards and back
    const int64_t now = sg::now_utime();
    for (size_t i = 0; i < 2; ++i) {
      pair[i].utime = now, pair[i].frame_number = k;
      bus.publish(i == 0 ? "CAMERA_LEFT" : "CAMERA_RIGHT", pair[i]);
    }
    // Paced as sg-camera-sim paces its frames (a camera's clock): asleep until the next, then
    // what LCM's thread received meanwhile (its receive times are stamped as it arrived).
    next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
    std::this_thread::sleep_until(next);
    while (bus.handle(0ms)) {
    }
  }
  const auto end = std::chrono::steady_clock::now() + 1s;  // the last ones in flight
  while (std::chrono::steady_clock::now() < end) bus.handle(50ms);
  const std::string text = vision.stop();
  predictor.stop();
  std::smatch m;
  if (std::regex_search(text, m, std::regex("OBJECT_POSITION handed to the bus: ([^\n]*)")))
    out.vision_own = m[1];
  if (std::regex_search(text, m,
                        std::regex("publish\\(\\) of OBJECT_POSITION returned [^:]*: ([^\n]*)")))
    out.vision_returned = m[1];
  if (std::regex_search(text, m, std::regex("handler \\([^)]*\\): ([^\n]*)")))
    out.vision_handler = m[1];
  if (std::regex_search(text, m, std::regex("delivery to the image's handler: ([^\n]*)")))
    out.vision_delivery = m[1];
  if (std::regex_search(text, m, std::regex("decoded by its worker (\\d+) times, in line (\\d+)")))
    out.worker = std::string(m[1]) + " by the worker, " + std::string(m[2]) + " in line";
  if (std::regex_search(text, m, std::regex("(\\d+) first images found sg-vision awake")))
    out.worker += "; " + std::string(m[1]) + " found it awake";
  if (std::regex_search(text, m, std::regex("CPU time: ([^\n]*)"))) out.vision_cpu = m[1];
}

void print(const Run& r) {
  auto ms = [](const sg::LatencyRecord& l, double p) {
    return l.count() ? l.percentile(p) / 1000.0 : 0.0;
  };
  std::printf("%-22s %6llu  %7.2f %7.2f   %8llu  %7.2f %7.2f   %s\n", r.name.c_str(),
              static_cast<unsigned long long>(r.position.count()), ms(r.position, 0.5),
              ms(r.position, 0.99), static_cast<unsigned long long>(r.trajectory.count()),
              ms(r.trajectory, 0.5), ms(r.trajectory, 0.99), r.vision_own.c_str());
  std::printf("%-22s %58s   of which the delivery:  %s\n", "", "", r.vision_delivery.c_str());
  std::printf("%-22s %58s   of which the handler:    %s\n", "", "", r.vision_handler.c_str());
  std::printf("%-22s %58s   first images decoded:    %s\n", "", "", r.worker.c_str());
  std::printf("%-22s %58s   to publish() returning:  %s\n", "", "", r.vision_returned.c_str());
  std::printf("%-22s %58s   sg-vision's CPU time:    %s\n", "", "", r.vision_cpu.c_str());
}

/// The lab key: $SG_LAB_KEY or ~/.config/stereograsp/lab.key when there, else one made in `dir`.
std::string lab_key(const std::string& dir) {
  try {
    const std::string path = sg::auth::default_key_path();
    if (std::filesystem::exists(path)) return path;
  } catch (const sg::auth::LabKeyError&) {
  }
  sg::auth::write_new_key_file(dir + "/lab.key");
  return dir + "/lab.key";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Camera message -> OBJECT_POSITION -> OBJECT_TRAJECTORY through sg-vision and "
      "sg-predictor, with JPEG (windows or whole) and raw frames."};
  int pairs = 300;
  double rate = 20;
  // Raw frames are 0.9 MB: LCM's default socket buffer drops their fragments (recv_buf_size).
  std::string url = "udpm://239.255.76.67:7961?ttl=0&recv_buf_size=16777216";
  app.add_option("--pairs", pairs, "stereo pairs a run")->check(CLI::Range(10, 100000));
  app.add_option("--rate", rate, "pairs a second (the predictor's period is set to match)")
      ->check(CLI::Range(1.0, 100.0));
  app.add_option("--lcm-url", url, "the bus (this host only: ttl=0)");
  bool region_only = false;
  int realtime = 0;
  app.add_option("--realtime-priority", realtime,
                 "sg-vision's vision.realtime_priority (SCHED_FIFO, memory locked; 0: off)")
      ->check(CLI::Range(0, 99));
  app.add_flag("--region-only", region_only,
               "only the JPEG runs with the windows decoded: as configured by default (the "
               "issue's figure), read through LCM, and asleep until frames come "
               "(busy_wait_ms 0)");
  CLI11_PARSE(app, argc, argv);
  try {
    const std::string dir =
        std::filesystem::temp_directory_path() / ("frame_path_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/predictor.yaml") << "predictor:\n  period: " << 1.0 / rate << "\n";
    std::printf("rendering and encoding 60 stereo frames...\n");
    const Frames frames = render(dir + "/cams.yaml");
    std::vector<Run> runs(region_only ? 4 : 6);
    runs[0].name = "JPEG, windows decoded";
    runs[1].name = "... not vouched for";
    runs[2].name = "... read through LCM";
    runs[3].name = "... asleep till frames";
    const RunSettings rs{url, dir, lab_key(dir), pairs, rate, realtime};
    run(rs, frames.jpeg, {}, runs[0]);
    run(rs, frames.jpeg, {"region", "direct", "", false}, runs[1]);
    run(rs, frames.jpeg, {"region", "lcm", ""}, runs[2]);
    run(rs, frames.jpeg, {"region", "direct", "0"}, runs[3]);
    if (!region_only) {
      runs[4].name = "JPEG, whole frames", runs[5].name = "raw BGR8";
      run(rs, frames.jpeg, {"full", "direct", ""}, runs[4]);
      run(rs, frames.raw, {}, runs[5]);
    }
    std::printf(
        "\n%d pairs at %.0f Hz, one host, sg-vision %s, ms from the frames' publication "
        "(utime):\n",
        pairs, rate,
        realtime ? ("at SCHED_FIFO " + std::to_string(realtime)).c_str()
                 : "on the ordinary scheduler");
    std::printf("%-22s %6s  %7s %7s   %8s  %7s %7s   %s\n", "frames", "points", "p50", "p99",
                "trajects", "p50", "p99",
                "sg-vision's own: second image received -> OBJECT_POSITION");
    for (const Run& r : runs) print(r);
    std::filesystem::remove_all(dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "frame_path_latency: %s\n", e.what());
    return 1;
  }
  return 0;
}
