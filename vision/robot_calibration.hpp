#pragma once

#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/config.hpp"
#include "vision/ball_fit.hpp"
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
  /// The ball's centre from the tool centre point, tool frame (m): the first guess of the
  /// hand-eye estimate, and the value kept in directions the stops cannot observe.
  Eigen::Vector3d ball_offset{0, 0, 0};
  /// Estimate the ball's offset in the tool frame together with the cameras (solve_hand_eye);
  /// false: the configured ball_offset is taken as exact.
  bool estimate_ball_offset = true;
  /// The estimated offset is kept only when it brings the RMS reprojection error to this
  /// fraction of the configured offset's or below. The ball's centre in an image where the
  /// gripper hides half its outline is off by a pixel or two, and that error turns with the
  /// tool, as an offset does; an offset that explains little more than such errors is not one.
  /// (A real 2 cm offset leaves the configured one several pixels of error.)
  double offset_gain = 0.75;
  /// rad: stops alternate a tilt of +tilt and -tilt about the tool's x and y axes (0: all
  /// tool-down). With tool-down stops that differ only in yaw the offset along the tool's axis
  /// moves every ball position alike and stays unobservable; a tilt makes it observable.
  double tilt = 0.0;
  /// A blob whose fitted circle has less of its outline than this (blob_t.fit_support) shows too
  /// little of the ball (the gripper hides it): it is not averaged. NaN support (a whole disc, no
  /// fit needed) always counts.
  double min_fit_support = 0.45;
  /// m: the ball's radius, for the model of its image at each stop (sphere_outline_centre);
  /// sg-calibrate takes vision.ball_radius. 0: unknown, the image's radius is used instead
  /// (sphere_centre_pixel, which does not model a part of the outline).
  double ball_radius = 0.035;
  double speed = 0.5;            ///< fraction of the arm's maximum
  int frames_per_stop = 10;      ///< blobs averaged per camera at each stop
  double settle = 0.5;           ///< s after arrival before blobs count
  int max_misses_per_stop = 60;  ///< frames without the ball before a stop is skipped
  double timeout = 30;           ///< s without progress before sg-calibrate gives up
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

/// What robot-guided calibration found: both cameras in the robot frame and where the ball sits
/// on the tool.
struct HandEyeSolution {
  StereoCalibration cameras;
  Eigen::Vector3d ball_offset{0, 0, 0};  ///< ball centre from the tool centre point, tool frame
  int offset_dims = 0;  ///< directions of the offset the stops observed (0-3); others as given
  int iterations = 0;   ///< Levenberg-Marquardt rounds of the joint solve
  bool offset_accepted = false;  ///< the estimate was kept (offset_gain); else as configured
  double rms_configured = 0;     ///< px, RMS reprojection error with the configured offset
  double rms_estimated = 0;      ///< px, with the estimated one
  int passes = 0;  ///< solves, each on the pixels the last one's cameras corrected (see solve)
  /// Per stop of RobotCalibration::stops() (NaN where skipped or unseen): the distance (px) in
  /// each camera between the ball's centre projected by the result and its corrected pixel.
  std::vector<std::array<double, 2>> residual;
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
  Eigen::Vector3d tool;  ///< commanded tool centre point
  Eigen::Vector3d rpy;   ///< commanded tool orientation
  Eigen::Vector3d ball;  ///< the ball's centre (tool + offset), robot frame
  std::array<Eigen::Vector2d, 2> pixel{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  std::array<double, 2> radius{0, 0};  ///< mean radius of the ball's image, px
  /// Each averaged blob's centre and the outline sectors it rests on (BallFit::arc): where a
  /// finger splits the ball's image the fit may take one part in one frame and the other in the
  /// next, centres px apart, so each is modelled on its own.
  std::array<std::vector<std::pair<Eigen::Vector2d, uint64_t>>, 2> blobs;
  std::array<int, 2> frames{0, 0};
  int misses = 0;
  int hidden = 0;   ///< blobs left out because the gripper hid too much (min_fit_support)
  int refused = 0;  ///< blobs refused: a centre not finite or off the image
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
///       ... on BLOB_LEFT/RIGHT: cal.on_blob(camera, utime, found, centre, fit_support);
///     }
///     HandEyeSolution s = cal.solve_hand_eye();   // cameras and the ball's offset on the tool
class RobotCalibration {
 public:
  explicit RobotCalibration(const RobotCalibrationParams& params, int64_t first_sequence = 1);

  /// The move to command now, once per stop (nullopt while a move is under way or when done).
  std::optional<ArmTarget> next_target();
  /// The arm's report: the last command it executed and whether it is at rest.
  void on_arm_status(int64_t utime, int64_t last_executed_sequence, bool idle);
  /// The arm refused command `sequence` (out of reach, say): its stop is skipped with `reason`.
  void on_arm_rejected(int64_t sequence, const std::string& reason);
  /// One camera's (0 left, 1 right) blob: the ball's centre (blob_t.centre: the fitted circle's
  /// when the gripper hides part of it) and the share of its outline that supported the fit
  /// (NaN: a whole disc, no fit), its image's radius in px (0: unknown) and the sectors of the
  /// outline the centre rests on (blob_t.fit_arc).
  void on_blob(int camera, int64_t utime, bool found, const Eigen::Vector2d& centre,
               double fit_support = std::nan(""), double radius = 0, uint64_t arc = kWholeArc);

  bool done() const { return current_ >= stops_.size(); }
  /// "stop 4 of 18: collecting (left 3/10, right 2/10)" and the like.
  std::string progress() const;
  const std::vector<CalibrationStop>& stops() const { return stops_; }

  /// The parameters the grid was made from.
  const RobotCalibrationParams& params() const { return params_; }

  /// The cameras and the ball's offset on the tool, hand-eye style. At stop i the tool centre
  /// point is t_i and its orientation R_i, so the ball's centre is X_i = t_i + R_i d for the
  /// unknown offset d (tool frame). Minimised over both cameras' P and d, the reprojection error
  ///     sum_i,c || pi(P_c [X_i; 1]) - x_ic ||^2
  /// starts from both cameras' DLT (eq. 5-6, refined) at the configured d, then Levenberg-
  /// Marquardt runs on both P (row-major, 24 numbers) and d together (d pi / d X =
  /// (A_0 - u A_2; A_1 - v A_2) / w for P = [A | b], w = A_2 X + b_2), until d moves less than
  /// 0.1 µm (at most 100 rounds); the cameras are the DLT's again at the d found.
  /// Only directions of d that the stops observe are estimated: those where R_i e differs from
  /// stop to stop by at least 5% RMS (the eigenvectors of sum (R_i - R_mean)^T (R_i - R_mean));
  /// along the others d moves every X_i alike, which the DLT absorbs, and the configured
  /// ball_offset is kept. The estimate is kept only when it cuts the reprojection error to
  /// offset_gain of the configured offset's. With estimate_ball_offset false, d is the
  /// configured offset. Throws
  /// CalibrationInputError when fewer than 6 stops were seen by both cameras.
  /// The pixels are the image's centres, which lie off the projection of the ball's centre off
  /// the optical axis, by several px where a circle was fitted to part of the outline of the
  /// ball's image, an ellipse (sphere_image.hpp). So the solve runs again, each time after the
  /// first on the measured pixels corrected by the difference between the projection of the
  /// ball's centre and the centre the tracker's fit finds on the same sectors of the ball's exact
  /// image, both with the last pass's cameras and offset (sphere_outline_centre; with
  /// ball_radius 0, sphere_centre_pixel() from each stop's image radius).
  HandEyeSolution solve_hand_eye() const;
  /// Solves of solve_hand_eye(): the first on the measured pixels, then on corrected ones until
  /// no correction moves by more than kPixelsSettled (px), at most kMaxPasses in all.
  static constexpr int kMaxPasses = 12;
  static constexpr double kPixelsSettled = 0.005;
  /// solve_hand_eye().cameras.
  StereoCalibration solve() const { return solve_hand_eye().cameras; }

 private:
  enum class Phase { kSend, kMoving, kSettling };
  void finish_stop();

  RobotCalibrationParams params_;
  std::vector<CalibrationStop> stops_;
  std::array<Eigen::Vector2d, 2> sums_;
  std::array<double, 2> radius_sums_{0, 0};
  size_t current_ = 0;
  Phase phase_ = Phase::kSend;
  int64_t sequence_;
  int64_t arrived_utime_ = 0;
};

}  // namespace sg::vision
