#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "common/config.hpp"
#include "vision/calibration_file.hpp"
#include "vision/dlt.hpp"

namespace sg::vision {

/// The robot-guided calibration: the arm holds the ball at a grid of positions through the
/// workspace; at each the ball's pixel in both cameras is averaged; the DLT of both cameras is
/// solved in the robot's frame (the paper's correspondence between image and robot coordinates).
///
/// The default box is inside the A465's reach with the tool pointing down (its 0.15 m tool puts
/// the wrist centre 0.226 m above the tool centre point; the wrist must stay 0.365 to 0.635 m
/// from the shoulder at z = 0.33 m) and inside the simulated cameras' views.
struct RobotCalibrationParams {
  Eigen::Vector3d box_min{0.38, -0.15, 0.08};  ///< grid corners, robot frame (m)
  Eigen::Vector3d box_max{0.52, 0.15, 0.24};
  int nx = 3, ny = 3, nz = 2;  ///< grid points per axis (at least 12 in all)
  /// The tool's roll, pitch, yaw at every stop; unset: pointing down, the fingers across the line
  /// from the waist axis, (pi, 0, atan2(y, x) + pi), which keeps joint 6 near zero.
  std::optional<Eigen::Vector3d> tool_rpy;
  Eigen::Vector3d ball_offset{0, 0, 0};  ///< ball centre from the tool centre point, tool frame
  double speed = 0.5;                    ///< fraction of the arm's maximum
  int frames_per_stop = 10;              ///< blobs averaged per camera at each stop
  double settle = 0.5;                   ///< s after arrival before blobs count
  int max_misses_per_stop = 60;          ///< frames without the ball before a stop is skipped
  double timeout = 30;                   ///< s without progress before sg-calibrate gives up
  int image_width = 640, image_height = 480;
};

/// The tool-down orientation for a stop at `position`: (pi, 0, atan2(y, x) + pi) wrapped to
/// (-pi, pi]; joint 6 stays near zero (the same rule as sg-arm-ctl's default).
Eigen::Vector3d tool_down_rpy(const Eigen::Vector3d& position);

/// RobotCalibrationParams from the `calibrate_robot` section (every key optional, defaults as
/// above): box_min, box_max ([x, y, z] m), grid ([nx, ny, nz]), tool_rpy ([r, p, y] rad),
/// ball_offset ([x, y, z] m), speed, frames_per_stop, settle, max_misses_per_stop. Throws
/// ConfigError naming a bad key (a list of the wrong length, box_min not below box_max, fewer
/// than 12 points or 2 heights, speed outside (0, 1]).
RobotCalibrationParams load_robot_calibration_params(const Config& config);

/// A move the procedure wants the arm to make.
struct ArmTarget {
  int64_t sequence = 0;
  Eigen::Vector3d position;
  Eigen::Vector3d rpy;
  double speed = 0.5;
};

/// One stop of the grid and what was seen there.
struct CalibrationStop {
  Eigen::Vector3d tool;  ///< commanded tool centre point
  Eigen::Vector3d rpy;   ///< commanded tool orientation
  Eigen::Vector3d ball;  ///< the ball's centre (tool + offset), robot frame
  std::array<Eigen::Vector2d, 2> pixel{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  std::array<int, 2> frames{0, 0};
  int misses = 0;
  bool skipped = false;
  std::string rejected;  ///< why the arm refused the move (then skipped)
};

/// The procedure as a state machine driven by messages (no clock, no bus): ask next_target() for
/// the move to command, feed it ARM_STATUS and BLOB_* contents, and solve() when done().
///
///     RobotCalibration cal(params);
///     while (!cal.done()) {
///       if (auto t = cal.next_target()) publish_arm_command(*t);
///       ... on ARM_STATUS: cal.on_arm_status(utime, last_executed_sequence, idle);
///       ... on BLOB_LEFT/RIGHT: cal.on_blob(camera, utime, found, centroid);
///     }
///     StereoCalibration c = cal.solve();
class RobotCalibration {
 public:
  explicit RobotCalibration(const RobotCalibrationParams& params, int64_t first_sequence = 1);

  /// The move to command now, once per stop (nullopt while a move is under way or when done).
  std::optional<ArmTarget> next_target();
  /// The arm's report: the last command it executed and whether it is at rest.
  void on_arm_status(int64_t utime, int64_t last_executed_sequence, bool idle);
  /// The arm refused command `sequence` (out of reach, say): its stop is skipped with `reason`.
  void on_arm_rejected(int64_t sequence, const std::string& reason);
  /// One camera's (0 left, 1 right) blob.
  void on_blob(int camera, int64_t utime, bool found, const Eigen::Vector2d& centroid);

  bool done() const { return current_ >= stops_.size(); }
  /// "stop 4 of 18: collecting (left 3/10, right 2/10)" and the like.
  std::string progress() const;
  const std::vector<CalibrationStop>& stops() const { return stops_; }

  /// The parameters the grid was made from.
  const RobotCalibrationParams& params() const { return params_; }

  /// DLT for both cameras in the robot frame from the stops seen by both; throws
  /// CalibrationInputError when fewer than 6 remain. `rms` per camera in the result.
  StereoCalibration solve() const;

 private:
  enum class Phase { kSend, kMoving, kSettling };
  void finish_stop();

  RobotCalibrationParams params_;
  std::vector<CalibrationStop> stops_;
  std::array<Eigen::Vector2d, 2> sums_;
  size_t current_ = 0;
  Phase phase_ = Phase::kSend;
  int64_t sequence_;
  int64_t arrived_utime_ = 0;
};

}  // namespace sg::vision
