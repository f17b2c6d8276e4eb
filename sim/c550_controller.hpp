#pragma once

/// The C550 controller and its arm as a pure model (docs/arm.md): joint motion, gripper, grasp
/// of the simulated ball, the interaction delay and the memory that ACI transfers read and write.
/// No I/O and no clock: every call takes the simulation time `t` in seconds, which must not go
/// backwards from one command to the next. sg-c550-sim wraps it in a serial line
/// (c550_emulator.hpp); a batch simulation can drive it in-process.
///
///     sg::sim::C550Controller c550(sg::arm::ArmGeometry::a465());
///     if (auto r = c550.move_joints(target, t); !r) log(r.error);   // "*** 73 JOINT LIMIT ..."
///     double ack_at = t + c550.interaction_delay();                  // 0.72 .. 0.84 s later
///     sg::arm::Joints now = c550.joints(t + 0.3);                    // mid-motion
///     (void)c550.close(t + 2.0, ball_centre);                        // holding() if near the TCP
///
/// What is modelled rather than known (the C550's internals are not public):
///  - a motion is synchronous joint interpolation at constant joint speed (no acceleration): all
///    joints start at the command and arrive together after arm::motion_time() at the SPEED
///    fraction of the joints' maximum speeds;
///  - the C550's motion queue is not public: a new motion command does not queue, it retargets
///    at once from the current interpolated position;
///  - the gripper moves between open and closed widths at a constant rate (gripper_time for the
///    full stroke); a CLOSE grasps the ball when its true centre is within grasp_tolerance of the
///    tool centre point at the time of the command and the fingers are open wider than the ball,
///    and the fingers then stop on the ball (2 * ball_radius);
///  - with start_holding the controller powers up with the ball already between the fingers.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "arm_driver/kinematics.hpp"

namespace sg::sim {

/// The model's settings. Times in seconds, lengths in metres, angles in radians.
struct C550Params {
  double delay_min = 0.72;            ///< shortest interaction delay (the paper: 0.72 to 0.84 s)
  double delay_max = 0.84;            ///< longest interaction delay
  uint32_t seed = 1;                  ///< seeds the delay draws
  int speed_percent = 50;             ///< initial SPEED, percent of the joints' maximum speeds
  double gripper_time = 0.4;          ///< full stroke, open <-> closed
  double gripper_open_width = 0.08;   ///< between the fingers when open
  double gripper_closed_width = 0.0;  ///< between the fingers when closed on nothing
  double grasp_tolerance = 0.02;      ///< ball centre to TCP distance that still grasps
  double ball_radius = 0.035;
  /// Power up holding the ball: the fingers closed on it (2 * ball_radius) and holding() true
  /// until the first OPEN, as if it had been put in the gripper by hand (robot-guided
  /// calibration, docs/calibration.md).
  bool start_holding = false;
  /// READY, also the joints at power-up: elbow and wrist at 90 degrees, which with the A465
  /// puts the flange 0.33 m in front of the waist axis at z = 0.559 m, tool z axis straight down.
  arm::Joints ready =
      (arm::Joints() << 0, 0, std::numbers::pi / 2, 0, std::numbers::pi / 2, 0).finished();
};

/// The outcome of a command: ok, or the controller's error line (`*** 73 JOINT LIMIT ...`).
struct [[nodiscard]] CommandResult {
  std::string error;  ///< empty when the command was accepted
  bool ok() const { return error.empty(); }
  explicit operator bool() const { return ok(); }
};

/// The controller and arm. Not thread-safe.
class C550Controller {
 public:
  /// Throws std::invalid_argument naming the bad parameter (delays, speed, gripper, ready joints
  /// outside the limits).
  explicit C550Controller(arm::ArmGeometry geometry, C550Params params = {});

  const arm::ArmGeometry& geometry() const { return geometry_; }
  const C550Params& params() const { return params_; }

  /// Settles what has finished by `t` (a motion that has arrived, the gripper). Queries work
  /// without it; commands call it themselves.
  void advance(double t);

  /// True joint angles at `t` (the linear interpolation while moving).
  arm::Joints joints(double t) const;
  /// Base -> tool centre point at `t` (forward kinematics of joints(t)).
  Eigen::Isometry3d tool_pose(double t) const;
  /// Between the fingers at `t`, metres.
  double gripper_opening(double t) const;
  /// True from a CLOSE that grasped the ball until the next OPEN.
  bool holding() const { return holding_; }
  /// A CLOSE as it happened: when, where the tool centre point was, the ball centre it was given,
  /// and whether the controller then held the ball.
  struct CloseRecord {
    double t = 0;
    Eigen::Vector3d tcp = Eigen::Vector3d::Zero();
    std::optional<Eigen::Vector3d> ball;
    bool holding = false;
  };
  /// Every CLOSE so far, in order (the trials' miss distance).
  const std::vector<CloseRecord>& closes() const { return closes_; }
  /// Where the tool centre point was when an OPEN last let a held ball go; nullopt before.
  const std::optional<Eigen::Vector3d>& released_at() const { return released_at_; }
  /// When the last accepted arm motion (MA, MOVE, JOINT, READY) started; 0 before any.
  double last_motion_start() const { return motion_.start; }
  /// True while the arm or the gripper is moving at `t`.
  bool moving(double t) const { return t < settle_time(); }
  /// When the current arm motion and gripper stroke have both ended (FINISH answers then).
  double settle_time() const;
  int speed_percent() const { return speed_percent_; }

  /// SPEED: 1..100 percent; otherwise `*** 10 SPEED ...` and no change. Applies to later moves.
  CommandResult set_speed(int percent);
  /// MA: a synchronous joint move to `target` starting at `t`. Refused, the arm not moving, with
  /// `*** 73 JOINT LIMIT: joint N ...` when a joint is not finite or outside its limits.
  CommandResult move_joints(const arm::Joints& target, double t);
  /// MOVE to a Cartesian TCP pose (metres; roll, pitch, yaw radians) by the inverse-kinematics
  /// solution nearest the current joints. Refused with `*** 72 LOCATION OUT OF RANGE: ...` when
  /// there is none.
  CommandResult move_pose(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy, double t);
  /// READY: a joint move to params().ready.
  CommandResult ready(double t);
  /// ABORT: the arm stops where it is at `t` (the gripper finishes its stroke).
  void abort(double t);
  /// OPEN: the gripper opens; a held ball is released.
  void open(double t);
  /// CLOSE: the gripper closes; grasps `ball_centre` (the ball's true centre, base frame) when it
  /// is within grasp_tolerance of the TCP at `t` and the fingers are open wider than the ball.
  void close(double t, const std::optional<Eigen::Vector3d>& ball_centre);

  /// The time from a motion command to the controller's answer: U[delay_min, delay_max] from
  /// the controller's own mt19937 seeded by params().seed (the same sequence for the same seed).
  double interaction_delay();

  // ---- Memory for ACI transfers (docs/arm.md, "Memory types") ----
  /// Segments of 64 KiB (memtype 0x00), zero at power-up.
  static constexpr int kSegmentSize = 65536;
  /// The RAPL pointer list (memtype 0x40): this many 4-byte little-endian pointers, read-only.
  static constexpr int kPointerCount = 16;

  /// Empty when the transfer is allowed, else why not (unknown memory type, past the end of a
  /// segment or the pointer list, a write to the read-only pointer list or the 0x48 session
  /// byte, a session read that is not 1 byte).
  std::string memory_access_error(uint8_t memtype, uint16_t segment, uint16_t offset, int length,
                                  bool write) const;
  /// `length` bytes at segment:offset; memtype 0x48 reads the session byte 0x01. Throws
  /// std::invalid_argument with memory_access_error() when not allowed.
  std::vector<uint8_t> read_memory(uint8_t memtype, uint16_t segment, uint16_t offset,
                                   int length) const;
  /// Writes segment memory (memtype 0x00); throws std::invalid_argument when not allowed.
  void write_memory(uint8_t memtype, uint16_t segment, uint16_t offset,
                    std::span<const uint8_t> data);

 private:
  /// A straight line in joint space from `from` at `start` to `to` at `end`.
  struct Motion {
    arm::Joints from = arm::Joints::Zero();
    arm::Joints to = arm::Joints::Zero();
    double start = 0;
    double end = 0;
  };
  /// The fingers moving at constant rate from `from` at `start` to `to` at `end`.
  struct Stroke {
    double from = 0;
    double to = 0;
    double start = 0;
    double end = 0;
  };

  void check_time(double t, const char* command);
  void start_motion(const arm::Joints& target, double t);
  void start_stroke(double width, double t);
  std::array<uint8_t, 4 * kPointerCount> pointer_list() const;

  arm::ArmGeometry geometry_;
  C550Params params_;
  int speed_percent_;
  Motion motion_;
  Stroke stroke_;
  bool holding_ = false;
  std::vector<CloseRecord> closes_;
  std::optional<Eigen::Vector3d> released_at_;
  double last_command_time_ = 0;
  std::mt19937 rng_;
  std::map<uint16_t, std::vector<uint8_t>> segments_;
};

}  // namespace sg::sim
