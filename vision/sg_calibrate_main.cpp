// sg-calibrate: the cameras' calibration (section 4) and its registration to the robot's frame.
//
//   sg-calibrate dlt --left left.csv --right right.csv --out cams.yaml
//        each CSV line X,Y,Z,u,v: a point in the robot frame (m) and its pixel in that camera
//   sg-calibrate checkerboard --left dirL --right dirR --pattern 9x6 --square 0.025 --out cams.yaml
//   sg-calibrate robot --out cams.yaml [--box-min X Y Z --box-max X Y Z --grid NX NY NZ]
//        the arm holds the ball; sg-calibrate moves it (ARM_COMMAND) through a grid of 18
//        positions (the `calibrate_robot:` section of --config, or the flags), waits for
//        ARM_STATUS to report each arrival, averages BLOB_LEFT/RIGHT there, and solves the DLT of
//        both cameras in the robot frame; a stop the arm refuses or the cameras miss is skipped;
//        its ARM_COMMAND are signed with the lab key (--key, docs/security.md)
//   sg-calibrate register --calibration cams.yaml --points marks.csv --out robot.yaml
//        each CSV line X,Y,Z,u_left,v_left,u_right,v_right: a point known in the robot frame and
//        where both cameras see it; the calibration is moved into the robot's frame
// A file is written only when the whole calibration succeeded (never a partial one over a good
// one).

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "arm_driver/arm_commander.hpp"
#include "auth/lab_access.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "vision/checkerboard.hpp"
#include "vision/dlt.hpp"
#include "vision/image_folder.hpp"
#include "vision/registration.hpp"
#include "vision/robot_calibration.hpp"
#include "vision/triangulation.hpp"
#include "vision/vision_config.hpp"

namespace {

namespace fs = std::filesystem;
using sg::vision::CalibrationInputError;

/// Rows of `columns` numbers from a CSV file; a header line and '#' comments are skipped; errors
/// name the file and the line.
std::vector<std::vector<double>> read_rows(const std::string& path, size_t columns) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot open");
  std::vector<std::vector<double>> rows;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<double> row;
    std::stringstream cells(line);
    std::string cell;
    bool header = false;
    while (std::getline(cells, cell, ',')) {
      try {
        size_t used = 0;
        row.push_back(std::stod(cell, &used));
        if (cell.find_first_not_of(" \t\r", used) != std::string::npos)
          throw std::invalid_argument(cell);
      } catch (const std::exception&) {
        if (rows.empty() && number == 1) {
          header = true;
          break;
        }
        throw std::runtime_error(path + ":" + std::to_string(number) + ": '" + cell +
                                 "' is not a number");
      }
    }
    if (header) continue;
    if (row.size() != columns) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": expected " +
                               std::to_string(columns) + " numbers, found " +
                               std::to_string(row.size()));
    }
    rows.push_back(row);
  }
  return rows;
}

int run_dlt(const std::string& left_csv, const std::string& right_csv, int width, int height,
            const std::string& out) {
  sg::vision::StereoCalibration c;
  double rms[2];
  for (int i = 0; i < 2; ++i) {
    const std::string& path = i == 0 ? left_csv : right_csv;
    std::vector<sg::vision::Correspondence> points;
    for (const auto& r : read_rows(path, 5)) points.push_back({{r[0], r[1], r[2]}, {r[3], r[4]}});
    sg::vision::DltResult result;
    try {
      result = sg::vision::calibrate_dlt(points, width, height);
    } catch (const CalibrationInputError& e) {
      throw std::runtime_error(path + ": " + e.what());
    }
    std::printf("%s camera: %zu points, RMS reprojection error %.3f px (linear %.3f px)\n",
                i == 0 ? "left" : "right", points.size(), result.rms, result.rms_linear);
    (i == 0 ? c.left : c.right) = result.camera;
    rms[i] = result.rms;
  }
  c.rms_left = rms[0];
  c.rms_right = rms[1];
  c.source = "sg-calibrate dlt";
  sg::vision::write_calibration(out, c);
  std::printf("wrote %s\n", out.c_str());
  return 0;
}

int run_checkerboard(const std::string& left_dir, const std::string& right_dir,
                     const std::string& pattern, double square, const std::string& out) {
  int w = 0, h = 0;
  char x = 0;
  std::istringstream in(pattern);
  if (!(in >> w >> x >> h) || x != 'x' || w < 2 || h < 2)
    throw std::runtime_error("--pattern '" + pattern +
                             "': expected inner corners as COLSxROWS, e.g. 9x6");
  const auto left = sg::vision::list_images(left_dir), right = sg::vision::list_images(right_dir);
  size_t done = 0;
  const auto result = sg::vision::calibrate_checkerboard(
      left, right, {{w, h}, square}, [&](const std::string& file) {
        spdlog::info("finding the board in {} ({} of {})", fs::path(file).filename().string(),
                     ++done, left.size() + right.size());
      });
  std::printf("%-20s %-20s %-8s %10s %10s\n", "left", "right", "used", "rms left", "rms right");
  for (const auto& v : result.views) {
    if (v.used) {
      std::printf("%-20s %-20s %-8s %10.3f %10.3f\n", fs::path(v.left).filename().c_str(),
                  fs::path(v.right).filename().c_str(), "yes", v.rms_left, v.rms_right);
    } else {
      std::printf("%-20s %-20s dropped: %s\n", fs::path(v.left).filename().c_str(),
                  fs::path(v.right).filename().c_str(), v.dropped_because.c_str());
    }
  }
  const auto& c = result.calibration;
  std::printf(
      "RMS reprojection error: left %.3f px, right %.3f px, stereo %.3f px; baseline %.1f mm\n",
      c.rms_left, c.rms_right, result.rms_stereo,
      (c.right.centre() - c.left.centre()).norm() * 1e3);
  sg::vision::write_calibration(out, c);
  std::printf(
      "wrote %s (frame: the left camera's; move it to the robot's with `sg-calibrate register`)\n",
      out.c_str());
  return 0;
}

int run_register(const std::string& calibration_path, const std::string& points_csv,
                 const std::string& out) {
  const auto c = sg::vision::read_calibration(calibration_path);
  std::vector<Eigen::Vector3d> robot, seen;
  for (const auto& r : read_rows(points_csv, 7)) {
    const auto t = sg::vision::triangulate({&c.left, &c.right}, {{r[3], r[4]}, {r[5], r[6]}});
    robot.emplace_back(r[0], r[1], r[2]);
    seen.push_back(t.position);
  }
  sg::vision::RigidFit fit;
  try {
    fit = sg::vision::fit_rigid(robot, seen);
  } catch (const CalibrationInputError& e) {
    throw std::runtime_error(points_csv + ": " + e.what());
  }
  auto moved = sg::vision::change_world_frame(c, fit.transform);
  moved.source =
      c.source + ", registered to the robot frame with " + std::to_string(robot.size()) + " points";
  moved.date.clear();
  std::printf("registration: %zu points, RMS %.2f mm\n", robot.size(), fit.rms * 1e3);
  sg::vision::write_calibration(out, moved);
  std::printf("wrote %s\n", out.c_str());
  return 0;
}

/// What the robot calibration hears of ARM_STATUS. Handlers run inside LCM's C code: they record
/// an error, and the loop throws it.
struct ArmWatch {
  std::string error;
  int64_t last_rejected = 0;
  bool connected = false;  ///< no command before the driver reports its controller connected

  void on_status(const stereograsp::arm_status_t& s, sg::vision::RobotCalibration& cal) {
    using Status = stereograsp::arm_status_t;
    if (!connected) {
      if (s.state != Status::STATE_IDLE) return;
      connected = true;
      last_rejected = s.last_rejected_sequence;
    }
    if (s.last_rejected_sequence != last_rejected) {
      last_rejected = s.last_rejected_sequence;
      cal.on_arm_rejected(s.last_rejected_sequence, s.rejection_reason);
    }
    if (s.state == Status::STATE_ERROR || s.state == Status::STATE_DISCONNECTED)
      error = "the arm reports " + std::string(s.error.empty() ? "an error" : s.error);
    cal.on_arm_status(s.utime, s.last_executed_sequence, s.state == Status::STATE_IDLE);
  }
};

/// The ARM_COMMAND that takes the ball to a calibration stop, sent at `utime`.
stereograsp::arm_cmd_t command_to(const sg::vision::ArmTarget& t, int64_t utime) {
  stereograsp::arm_cmd_t cmd{};
  cmd.utime = utime;
  cmd.sequence = t.sequence;
  cmd.mode = stereograsp::arm_cmd_t::MODE_CARTESIAN;
  for (int i = 0; i < 3; ++i) cmd.position[i] = t.position[i], cmd.orientation[i] = t.rpy[i];
  cmd.gripper = stereograsp::arm_cmd_t::GRIPPER_KEEP;
  cmd.speed = t.speed;
  cmd.sender = "sg-calibrate";
  return cmd;
}

/// Warns of each skipped stop and why; returns how many were skipped.
int warn_skipped(const std::vector<sg::vision::CalibrationStop>& stops) {
  int skipped = 0;
  for (const auto& s : stops) {
    skipped += s.skipped;
    if (!s.rejected.empty()) {
      spdlog::warn("stop ({:.3f}, {:.3f}, {:.3f}) skipped: the arm refused it: {}", s.tool.x(),
                   s.tool.y(), s.tool.z(), s.rejected);
    } else if (s.skipped && s.refused * 2 > s.misses) {
      spdlog::warn(
          "stop ({:.3f}, {:.3f}, {:.3f}) skipped: {} blobs with a centre off the image "
          "(another sender on BLOB_*?)",
          s.tool.x(), s.tool.y(), s.tool.z(), s.refused);
    } else if (s.skipped && s.hidden * 2 > s.misses) {
      spdlog::warn("stop ({:.3f}, {:.3f}, {:.3f}) skipped: the gripper hid too much of the ball",
                   s.tool.x(), s.tool.y(), s.tool.z());
    } else if (s.skipped) {
      spdlog::warn("stop ({:.3f}, {:.3f}, {:.3f}) skipped: the ball was not seen by both cameras",
                   s.tool.x(), s.tool.y(), s.tool.z());
    }
  }
  return skipped;
}

/// The three stops the result reprojects worst, with where they are: a stop far worse than the
/// RMS is one to look at in sg-viewer.
void print_worst_stops(const sg::vision::RobotCalibration& cal,
                       const sg::vision::HandEyeSolution& h) {
  std::vector<std::pair<double, size_t>> worst;
  for (size_t i = 0; i < h.residual.size(); ++i) {
    const double r = std::max(h.residual[i][0], h.residual[i][1]);
    if (std::isfinite(r)) worst.emplace_back(r, i);
  }
  std::sort(worst.rbegin(), worst.rend());
  worst.resize(std::min<size_t>(worst.size(), 3));
  std::printf("worst stops (%d solves):", h.passes);
  for (const auto& [r, i] : worst) {
    const Eigen::Vector3d t = cal.stops()[i].tool;
    std::printf(" %zu (%.2f, %.2f, %.2f) left %.2f px right %.2f px;", i + 1, t.x(), t.y(), t.z(),
                h.residual[i][0], h.residual[i][1]);
  }
  std::printf("\n");
}

/// Solves the cameras and the ball's offset on the tool, prints what was found and writes them.
void solve_and_write(const sg::vision::RobotCalibration& cal, const std::string& out) {
  const int skipped = warn_skipped(cal.stops());
  int hidden = 0, refused = 0;
  for (const auto& s : cal.stops()) hidden += s.hidden, refused += s.refused;
  if (refused > 0)
    spdlog::warn("{} blobs refused: a centre off the {}x{} image", refused,
                 cal.params().image_width, cal.params().image_height);
  sg::vision::HandEyeSolution h;
  try {
    h = cal.solve_hand_eye();
  } catch (const CalibrationInputError& e) {
    throw std::runtime_error(e.what());
  }
  const Eigen::Vector3d mm = h.ball_offset * 1e3;
  h.cameras.source +=
      fmt::format(", ball offset on the tool ({:.1f}, {:.1f}, {:.1f}) mm", mm.x(), mm.y(), mm.z());
  std::printf("%zu stops (%d skipped); RMS reprojection error left %.3f px, right %.3f px\n",
              cal.stops().size(), skipped, h.cameras.rms_left, h.cameras.rms_right);
  std::printf(
      "ball offset on the tool (%.1f, %.1f, %.1f) mm: %s (%d of 3 directions observed; "
      "RMS reprojection %.3f px as configured, %.3f px estimated); %d blobs left out with "
      "the ball mostly hidden\n",
      mm.x(), mm.y(), mm.z(), h.offset_accepted ? "estimated" : "as configured", h.offset_dims,
      h.rms_configured, h.rms_estimated, hidden);
  print_worst_stops(cal, h);
  sg::vision::write_calibration(out, h.cameras);
  std::printf("wrote %s (robot frame)\n", out.c_str());
}

int run_robot(const std::string& url, const sg::vision::RobotCalibrationParams& params,
              const std::string& out, sg::auth::LabAccess& lab) {
  const double timeout_s = params.timeout;
  sg::install_shutdown_handlers();
  sg::Bus bus(url);
  lab.guard(bus);
  // Sequence numbers from the clock, so they are newer than any the driver has seen.
  sg::vision::RobotCalibration cal(params, sg::now_utime());
  ArmWatch arm;
  sg::arm::ArmCommander commander(bus, lab);  // signs; the lease released at the end
  bus.subscribe<stereograsp::arm_status_t>(
      "ARM_STATUS", [&](const auto& status, const auto&) { arm.on_status(status, cal); });
  bus.subscribe<stereograsp::blob_t>("BLOB_(LEFT|RIGHT)", [&](const auto& b, const auto&) {
    cal.on_blob(b.camera, b.utime, b.found, {b.centre[0], b.centre[1]}, b.fit_support, b.radius,
                static_cast<uint64_t>(b.fit_arc));
  });
  std::string last_progress;
  auto last_change = std::chrono::steady_clock::now();
  bus.spin([&] {
    if (!arm.error.empty())
      throw std::runtime_error(arm.error + " at " + cal.progress() + "; nothing written");
    if (!arm.connected) {
      if (std::chrono::steady_clock::now() - last_change > std::chrono::duration<double>(timeout_s))
        throw std::runtime_error("no ARM_STATUS with the arm connected and idle for " +
                                 std::to_string(static_cast<int>(timeout_s)) +
                                 " s (is sg-arm-driver running?); nothing written");
      return true;
    }
    if (auto t = cal.next_target()) commander.send(command_to(*t, sg::now_utime()));
    commander.tick();  // heartbeats keep the lease while the arm moves and dwells
    const std::string progress = cal.progress();
    if (progress != last_progress) {
      spdlog::info("{}", progress);
      last_progress = progress;
      last_change = std::chrono::steady_clock::now();
    }
    if (std::chrono::steady_clock::now() - last_change > std::chrono::duration<double>(timeout_s)) {
      throw std::runtime_error(
          "no progress for " + std::to_string(static_cast<int>(timeout_s)) + " s at " + progress +
          " (are sg-arm-driver and sg-vision running, and the ball in the gripper?)");
    }
    return !cal.done();
  });
  commander.release();
  if (!cal.done())
    throw std::runtime_error("interrupted at " + cal.progress() + "; nothing written");
  solve_and_write(cal, out);
  return 0;
}

/// What the subcommands' flags give.
struct Inputs {
  std::string left, right, out, pattern = "9x6", calibration, points;
  int width = 640, height = 480;
  double square = 0.025;
};

CLI::App* add_dlt(CLI::App& app, Inputs& in) {
  CLI::App* dlt = app.add_subcommand("dlt", "DLT from points known in the robot frame (eq. 1-6)");
  dlt->add_option("--left", in.left, "left camera's CSV: X,Y,Z,u,v per line")->required();
  dlt->add_option("--right", in.right, "right camera's CSV: X,Y,Z,u,v per line")->required();
  dlt->add_option("--width", in.width, "image width (px)")->capture_default_str();
  dlt->add_option("--height", in.height, "image height (px)")->capture_default_str();
  dlt->add_option("--out", in.out, "calibration file to write")->required();
  return dlt;
}

CLI::App* add_checkerboard(CLI::App& app, Inputs& in) {
  CLI::App* board = app.add_subcommand(
      "checkerboard", "Intrinsics, distortion and stereo extrinsics from board images");
  board->add_option("--left", in.left, "folder of left images")->required();
  board->add_option("--right", in.right, "folder of right images (paired by sorted name)")
      ->required();
  board->add_option("--pattern", in.pattern, "inner corners COLSxROWS")->capture_default_str();
  board->add_option("--square", in.square, "side of a square (m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  board->add_option("--out", in.out, "calibration file to write")->required();
  return board;
}

/// The robot subcommand: its flags stand for `calibrate_robot` keys (the flag wins).
CLI::App* add_robot(CLI::App& app, Inputs& in, sg::ConfigFlags& flags,
                    sg::auth::KeyOptions& key_options) {
  CLI::App* robot = app.add_subcommand(
      "robot", "Arm-guided: the arm carries the ball through a grid (section 4)");
  robot->add_option("--out", in.out, "calibration file to write")->required();
  robot->add_option("--width", in.width, "image width (px)")->capture_default_str();
  robot->add_option("--height", in.height, "image height (px)")->capture_default_str();
  sg::auth::add_key_options(*robot, key_options);  // its ARM_COMMAND are signed
  const auto keys = sg::declared_keys(sg::vision::load_robot_calibration_params);
  for (const char* key : {"frames_per_stop", "settle", "speed", "timeout", "box_min", "box_max",
                          "grid", "ball_offset", "tool_rpy"}) {
    std::string flag = std::string("--") + key;
    std::replace(flag.begin(), flag.end(), '_', '-');
    flags.add(*robot, flag, std::string("calibrate_robot.") + key, keys);
  }
  return robot;
}

CLI::App* add_register(CLI::App& app, Inputs& in) {
  CLI::App* reg = app.add_subcommand("register", "Move a calibration into the robot's frame");
  reg->add_option("--calibration", in.calibration, "calibration in the cameras' frame")->required();
  reg->add_option("--points", in.points, "CSV: X,Y,Z (robot frame), u_left,v_left,u_right,v_right")
      ->required();
  reg->add_option("--out", in.out, "calibration file to write")->required();
  return reg;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Calibrates the stereo cameras and registers them to the robot's frame.",
               "sg-calibrate"};
  app.require_subcommand(1);
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  Inputs in;
  CLI::App* dlt = add_dlt(app, in);
  CLI::App* board = add_checkerboard(app, in);
  sg::auth::KeyOptions key_options;
  CLI::App* robot = add_robot(app, in, common.flags, key_options);
  add_register(app, in);
  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    // Read in every mode, so a typo in calibrate_robot is caught by any sg-calibrate.
    sg::vision::RobotCalibrationParams robot_params =
        sg::vision::load_robot_calibration_params(config);
    if (*robot) {
      robot_params.image_width = in.width;
      robot_params.image_height = in.height;
      // The ball sg-vision looks for: its radius models the ball's image at each stop.
      robot_params.ball_radius = sg::vision::read_vision_settings(config).match.ball_radius;
      return sg::auth::with_lab_access(app.get_name(), key_options, [&](auto& lab) {
        return run_robot(common.lcm_url, robot_params, in.out, lab);
      });
    }
    if (*dlt) return run_dlt(in.left, in.right, in.width, in.height, in.out);
    if (*board) return run_checkerboard(in.left, in.right, in.pattern, in.square, in.out);
    return run_register(in.calibration, in.points, in.out);
  });
}
