#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "vision/calibration_file.hpp"
#include "vision/dlt.hpp"

namespace sg::vision {

/// The robot-guided calibration: the arm holds the ball at a grid of positions through the
/// workspace; at each the ball's pixel in both cameras is averaged; the DLT of both cameras is
/// solved in the robot's frame (the paper's correspondence between image and robot coordinates).
struct RobotCalibrationParams {
  Eigen::Vector3d box_min{0.32, -0.22, 0.06};  ///< grid corners, robot frame (m)
  Eigen::Vector3d box_max{0.58, 0.22, 0.26};
  int nx = 3, ny = 3, nz = 2;                   ///< grid points per axis (at least 12 in all)
  Eigen::Vector3d tool_rpy{0.0, M_PI, 0.0};     ///< gripper pointing down
  Eigen::Vector3d ball_offset{0, 0, 0};         ///< ball centre from the tool centre point, tool frame
  double speed = 0.5;                           ///< fraction of the arm's maximum
  int frames_per_stop = 10;                     ///< blobs averaged per camera at each stop
  double settle = 0.5;                          ///< s after arrival before blobs count
  int max_misses_per_stop = 60;                 ///< frames without the ball before a stop is skipped
  int image_width = 640, image_height = 480;
};

/// A move the procedure wants the arm to make.
struct ArmTarget {
  int64_t sequence = 0;
  Eigen::Vector3d position;
  Eigen::Vector3d rpy;
  double speed = 0.5;
};

/// One stop of the grid and what was seen there.
struct CalibrationStop {
  Eigen::Vector3d tool;       ///< commanded tool centre point
  Eigen::Vector3d ball;       ///< the ball's centre (tool + offset), robot frame
  std::array<Eigen::Vector2d, 2> pixel{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  std::array<int, 2> frames{0, 0};
  int misses = 0;
  bool skipped = false;
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
  /// One camera's (0 left, 1 right) blob.
  void on_blob(int camera, int64_t utime, bool found, const Eigen::Vector2d& centroid);

  bool done() const { return current_ >= stops_.size(); }
  /// "stop 4 of 18: collecting (left 3/10, right 2/10)" and the like.
  std::string progress() const;
  const std::vector<CalibrationStop>& stops() const { return stops_; }

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
