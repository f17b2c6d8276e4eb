// sg-camera-sim: the two cameras of the lab, simulated. Publishes CAMERA_LEFT, CAMERA_RIGHT
// (image_t) and GROUND_TRUTH (point3_t) at the frame rate, or writes two videos and a ground-truth
// CSV; draws the gripper where SIM_ARM_STATE says the arm is.
//
//   sg-camera-sim                                  # real time at 30 Hz on the bus
//   sg-camera-sim --rate 4 --scenario circle
//   sg-camera-sim --fast --frames 900 --write out/ # videos + ground_truth.csv + calibration.yaml
//   sg-camera-sim --snapshot pair.png              # one stereo pair, side by side

#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <thread>

#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "sim/camera_simulator.hpp"
#include "sim/frame_pacing.hpp"
#include "vision/calibration_file.hpp"
#include "vision/image_message.hpp"

namespace {

using namespace std::chrono;

struct Options {
  bool fast = false;
  int64_t frames = 0;
  int jpeg_quality = 90;
  std::string write_dir;
  std::string snapshot;
  int64_t snapshot_frame = 0;
  std::string calibration_out;
  std::vector<std::string> occlusions;
};

stereograsp::point3_t ground_truth(const sg::sim::StereoFrame& f, int64_t utime) {
  stereograsp::point3_t p{};
  p.utime = utime;
  p.visible = f.seen[0] && f.seen[1];
  for (int i = 0; i < 3; ++i) {
    p.position[i] = f.ball[i];
    p.position_sigma[i] = 0.0;
  }
  p.reprojection_error = std::nan("");
  p.seen_by = static_cast<int8_t>((f.seen[0] ? stereograsp::point3_t::SEEN_LEFT : 0) |
                                  (f.seen[1] ? stereograsp::point3_t::SEEN_RIGHT : 0));
  return p;
}

sg::sim::ArmState to_arm_state(const stereograsp::sim_arm_state_t& m) {
  sg::sim::ArmState arm;
  arm.present = true;
  arm.tool_position = {m.tool_position[0], m.tool_position[1], m.tool_position[2]};
  arm.tool_rpy = {m.tool_orientation[0], m.tool_orientation[1], m.tool_orientation[2]};
  arm.gripper_opening = m.gripper_opening;
  arm.holding_object = m.holding_object != 0;
  return arm;
}

void write_true_calibration(const sg::sim::CameraSimulator& sim, const std::string& path) {
  sg::vision::StereoCalibration c;
  c.left = sim.camera(0);
  c.right = sim.camera(1);
  c.source = "sg-camera-sim true calibration";
  sg::vision::write_calibration(path, c);
  spdlog::info("wrote the simulator's true calibration to {}", path);
}

int run_snapshot(sg::sim::CameraSimulator& sim, const Options& o) {
  sg::sim::StereoFrame frame;
  sim.render(o.snapshot_frame, {}, frame);
  cv::Mat pair;
  cv::hconcat(frame.image[0], frame.image[1], pair);
  if (!cv::imwrite(o.snapshot, pair)) throw std::runtime_error(o.snapshot + ": cannot write image");
  std::printf("wrote %s: frame %lld (t = %.2f s), ball at (%.3f, %.3f, %.3f) m, seen %s/%s\n",
              o.snapshot.c_str(), static_cast<long long>(o.snapshot_frame), frame.time,
              frame.ball.x(), frame.ball.y(), frame.ball.z(), frame.seen[0] ? "left" : "-",
              frame.seen[1] ? "right" : "-");
  return 0;
}

int run_write(sg::sim::CameraSimulator& sim, const Options& o, int64_t frames) {
  namespace fs = std::filesystem;
  fs::create_directories(o.write_dir);
  const double rate = sim.params().frame_rate;
  const cv::Size size(sim.camera(0).width(), sim.camera(0).height());
  cv::VideoWriter left(o.write_dir + "/left.avi", cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), rate,
                       size),
      right(o.write_dir + "/right.avi", cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), rate, size);
  if (!left.isOpened() || !right.isOpened())
    throw std::runtime_error(o.write_dir + ": cannot open the video files for writing");
  std::ofstream csv(o.write_dir + "/ground_truth.csv");
  if (!csv) throw std::runtime_error(o.write_dir + "/ground_truth.csv: cannot write");
  csv << "frame,utime,time_s,x_m,y_m,z_m,seen_left,seen_right,visible_px_left,visible_px_right\n";
  write_true_calibration(sim, o.write_dir + "/calibration.yaml");
  const int64_t start_utime = sg::now_utime();
  const int64_t period_us = std::llround(1e6 / rate);
  sg::sim::StereoFrame frame;
  for (int64_t k = 0; k < frames && !sg::shutdown_requested(); ++k) {
    sim.render(k, {}, frame);
    left.write(frame.image[0]);
    right.write(frame.image[1]);
    char line[256];
    std::snprintf(line, sizeof line, "%lld,%lld,%.6f,%.6f,%.6f,%.6f,%d,%d,%.1f,%.1f\n",
                  static_cast<long long>(k), static_cast<long long>(start_utime + k * period_us),
                  frame.time, frame.ball.x(), frame.ball.y(), frame.ball.z(), frame.seen[0],
                  frame.seen[1], frame.visibility[0].visible_px, frame.visibility[1].visible_px);
    csv << line;
    if ((k + 1) % 100 == 0) spdlog::info("{} of {} frames written", k + 1, frames);
  }
  std::printf(
      "wrote %lld stereo frames to %s (left.avi, right.avi, ground_truth.csv, "
      "calibration.yaml)\n",
      static_cast<long long>(frames), o.write_dir.c_str());
  return 0;
}

int run_bus(sg::sim::CameraSimulator& sim, const Options& o, int64_t frames, bool jpeg,
            const std::string& url, const sg::auth::LabAccess& lab) {
  sg::Bus bus(url);
  lab.guard(bus);  // believes SIM_ARM_STATE only from sg-c550-sim
  bus.announce("sg-camera-sim");
  sg::sim::ArmState arm;
  bus.subscribe<stereograsp::sim_arm_state_t>(
      "SIM_ARM_STATE", [&](const stereograsp::sim_arm_state_t& m, const sg::ReceiveInfo&) {
        arm = to_arm_state(m);
      });
  const double rate = sim.params().frame_rate;
  const int64_t period_us = std::llround(1e6 / rate);
  const int64_t start_utime = sg::now_utime();
  const auto start = steady_clock::now();
  spdlog::info("publishing CAMERA_LEFT, CAMERA_RIGHT, GROUND_TRUTH at {} Hz ({}{})", rate,
               jpeg ? "JPEG" : "raw BGR", o.fast ? ", as fast as possible" : "");
  sg::sim::StereoFrame frame;
  sg::sim::FramePacing pacing(period_us, o.fast ? 0 : std::llround(sim.params().max_lag * 1e6));
  int64_t k = 0, published = 0;
  for (; (frames == 0 || k < frames) && !sg::shutdown_requested(); ++k) {
    if (!o.fast) {
      std::this_thread::sleep_until(start + microseconds(k * period_us));
      const int64_t late = pacing.skipped();
      k = pacing.next_frame(k, duration_cast<microseconds>(steady_clock::now() - start).count(),
                            frames);
      if (late == 0 && pacing.skipped() > 0)
        spdlog::warn(
            "rendering cannot keep {} Hz: dropping frames later than {} s, as a camera "
            "would (camera_sim.max_lag)",
            rate, sim.params().max_lag);
      if (frames != 0 && k >= frames) break;
    }
    while (bus.handle(milliseconds(0))) {
    }
    // Capture time: the frame's place on the timeline (real time, or simulated with --fast).
    const int64_t utime = start_utime + k * period_us;
    sim.render(k, arm, frame);
    bus.publish("CAMERA_LEFT", sg::vision::encode_image(frame.image[0], stereograsp::image_t::LEFT,
                                                        k, utime, jpeg, o.jpeg_quality));
    bus.publish("CAMERA_RIGHT",
                sg::vision::encode_image(frame.image[1], stereograsp::image_t::RIGHT, k, utime,
                                         jpeg, o.jpeg_quality));
    bus.publish("GROUND_TRUTH", ground_truth(frame, utime));
    ++published;
  }
  const double seconds = duration<double>(steady_clock::now() - start).count();
  std::printf("published %lld stereo frames in %.2f s (%.1f per second), dropped %lld late\n",
              static_cast<long long>(published), seconds, published / std::max(seconds, 1e-9),
              static_cast<long long>(pacing.skipped()));
  return bus.publish_errors() == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulated stereo cameras: renders the red ball, the lab and the gripper.",
               "sg-camera-sim"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  Options o;
  const auto keys = sg::declared_keys(sg::sim::load_sim_params);
  common.flags.add(app, "--rate", "camera_sim.rate_hz", keys);
  common.flags.add(app, "--max-lag", "camera_sim.max_lag", keys);
  app.add_flag("--fast", o.fast,
               "render as fast as possible (simulated time) instead of real time");
  app.add_option("--frames", o.frames, "stop after this many stereo frames (0: until Ctrl-C)");
  common.flags.add(app, "--encoding", "camera_sim.encoding", keys);
  app.add_option("--jpeg-quality", o.jpeg_quality, "JPEG quality")->check(CLI::Range(1, 100));
  app.add_option("--write", o.write_dir,
                 "write DIR/left.avi, right.avi, ground_truth.csv, calibration.yaml instead of "
                 "publishing (default 300 frames)");
  app.add_option("--snapshot", o.snapshot, "write one stereo pair, side by side, to a PNG");
  app.add_option("--snapshot-frame", o.snapshot_frame, "frame to snapshot (default 0)");
  app.add_option("--calibration-out", o.calibration_out,
                 "also write the simulator's true calibration to this file");
  common.flags.add(app, "--scenario", "scenario.kind", keys);
  common.flags.add(app, "--seed", "scenario.seed", keys);
  app.add_option("--occlusion", o.occlusions,
                 "a total occlusion START:DURATION in seconds (repeatable)");

  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    sg::sim::SimParams params = sg::sim::load_sim_params(config);
    for (const std::string& spec : o.occlusions) {
      double start = 0, duration = 0;
      char colon = 0;
      std::istringstream in(spec);
      if (!(in >> start >> colon >> duration) || colon != ':' || duration < 0)
        throw std::runtime_error("--occlusion '" + spec + "': expected START:DURATION in seconds");
      params.occlusion.episodes.push_back({start, duration});
    }
    const bool jpeg = params.encoding != "raw";
    sg::install_shutdown_handlers();
    sg::sim::CameraSimulator sim(params);
    if (!o.calibration_out.empty()) write_true_calibration(sim, o.calibration_out);
    if (!o.snapshot.empty()) return run_snapshot(sim, o);
    if (!o.write_dir.empty()) return run_write(sim, o, o.frames > 0 ? o.frames : 300);
    return sg::auth::with_lab_access(app.get_name(), key_options, [&](auto& lab) {
      return run_bus(sim, o, o.frames, jpeg, common.lcm_url, lab);
    });
  });
}
