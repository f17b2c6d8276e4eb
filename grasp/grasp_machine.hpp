#pragma once

/// The grasp state machine of the paper's section 6 (figure 4): states q0 hand opened,
/// q1 approaching, q2 grasping, q3 hand closed, q4 object lifted; actions a0 open hand,
/// a1 approach object, a2 close hand, a3 lift object. Before a grasp is asked for, the arm
/// tracks the ball: it follows the predicted position at a stand-off distance above it.
///
/// The machine is pure: no clock and no bus. A shell (sg-grasp) turns GRASP_COMMAND,
/// OBJECT_TRAJECTORY, OBJECT_POSITION and ARM_STATUS into the on_*() calls, asks take_request()
/// for the next ARM_COMMAND after each of them, asks arm_need() whether to keep the commander
/// lease (heartbeats, GraspNode), and publishes status() on GRASP_STATUS. Times are
/// microseconds since the Unix epoch, lengths metres, in the robot base frame.
///
/// A start does nothing unasked. The machine sends nothing until an operator's command asks for
/// it. Its starting state comes from the first ARM_STATUS: the gripper reported CLOSED gives
/// q3 hand closed, idle (the arm may hold the ball: release opens it); anything else q0 idle.
/// (A command taken before that first status that the closed hand forbids, track or grasp, is
/// cancelled then, with a message.) A grasp asked for in q0 while the gripper is not reported
/// OPEN plans a0 first, and the approach follows it.
///
/// One request in flight. The C550 answers one interaction every 0.72-0.84 s and the driver
/// keeps only the latest command, so the machine sends a new request only after ARM_STATUS
/// reported the previous one executed (last_executed_sequence) or rejected
/// (last_rejected_sequence): each target is computed just before the controller can act on it,
/// from the newest prediction. The one exception is abort, which is sent at once (the driver's
/// latest-wins slot makes the STOP the next thing on the line).
///
/// A lost request is resent, a driver restart is not. A request in flight that ARM_STATUS does
/// not show received (last_received_sequence, last_executed_sequence and last_rejected_sequence
/// all differ from its sequence) resend_after (0.5 s) after it was sent or last resent is sent
/// again: the same sequence and content (the driver executes a sequence once; the shell signs
/// the copy anew), counted in resends(). When ARM_STATUS's driver_start_utime changes with a
/// request in flight (the driver restarted; the old one may have executed it), the request is
/// not resent: it is abandoned as failed ("driver restarted") and the next one is computed afresh
/// under a new sequence. So is one in flight when ARM_STATUS shows a new watchdog stop (the
/// driver's STOP replaced the command it held). A request with no answer for kAnswerTimeout (or 8
/// delays, whichever is longer) since it was first sent is given up and treated as failed.
///
/// Rejections are backed off. After the k-th consecutive rejection (reset when a request is
/// executed) the next request waits min(kRetryFirst * 2^(k-1), kRetryLongest): 0.25, 0.5, 1, 2,
/// 4, 4 s ... (an operator's abort waits for nothing). A rejection whose reason says another
/// sender holds the commander lease ("arm commanded by 'sg-arm-ctl@bench:77'") shows as
/// "waiting: arm commanded by 'sg-arm-ctl@bench:77'" until a request is executed.
///
/// A silent ARM_STATUS stops the requests. No ARM_STATUS for more than arm_status_timeout
/// (1.0 s; the driver publishes at 10 Hz) makes no request (but an abort's STOP, which is safe
/// and obeyed from anyone) and no heartbeat (arm_need() kSilent) until statuses return;
/// arm_status_silence() says for how long (GraspNode shows "ARM_STATUS silent for 1.3 s").
///
/// The commander lease (arm_need(), see ArmNeed). The machine wants the arm while a request is
/// in flight, a one-off request is planned, it tracks with a fresh track, grasps, homes, backs
/// off, or the arm still moves from one of its own commands; the shell then sends heartbeats,
/// and one MODE_RELEASE when it stops wanting it. While tracking, a track gone stale is kSilent:
/// no heartbeat, so the driver's watchdog stops the arm (status().message says so), until the
/// track returns.
///
/// Interception. A Cartesian target aims where the ball will be when the gripper gets there:
/// intercept() (interception.hpp) with lead = delay_estimate(). Tracking uses the offset
/// (0, 0, standoff) and after_start = 0; the approach (a1) uses offset 0 and after_start = one
/// delay, because its GRIPPER_CLOSE (a2) travels in the same arm_cmd_t and the controller
/// executes the CLOSE one delay after the motion starts. A target is refused (no request, a
/// message in status()) when intercept() fails or the target is below table_z + table_margin or
/// outside the workspace box; the machine stays where it is and tries again on the next
/// take_request().
///
/// Closing when sure (issue 17). The approach carries the CLOSE, so it is sent only when the
/// interception is sure enough: with the path's own 1-sigma error at the arrival time T
/// (PredictedPath::sigma_at, the predictor's estimate), the arm's and the calibration's error
/// arm_sigma, and the controller's timing spread timing_sigma times the ball's predicted speed,
///
///     sigma_close = sqrt(|sigma(T)|^2 + arm_sigma^2 + (|p'(T)| timing_sigma)^2),
///
/// the approach goes when confidence * sigma_close <= tolerance (2 x 10 mm for the 20 mm the
/// gripper forgives). Otherwise the arm keeps tracking above the ball in q1 and tries again at
/// the next take_request(), status().message saying "waiting to close: 2 sigma 31 mm > 20 mm
/// tolerance (5.2 s left)"; an occlusion then ends before the hand closes. At max_wait after the
/// grasp command it closes on its best guess, and says so. A path without sigmas (the
/// --no-prediction baseline) closes at once, as before.
///
/// Re-planning (issue 17). The approach's CLOSE reaches the controller one delay after the
/// approach is sent (sg-arm-driver sends the MA, waits for its reply, then the CLOSE), and a newer
/// command waiting in the driver's slot by then makes the CLOSE give way (ArmDriver, "A gripper
/// action gives way"). So while q2's approach is in flight and younger than delay_estimate() -
/// replan_margin, every newer trajectory is checked against it: when it puts the ball at the
/// approach's T more than replan_shift from the approach's aim, or its sigma_close at T no longer
/// fits the tolerance (a turn seen after the approach began), the machine sends at once the
/// request q1 would send now: a new approach with its CLOSE (still q2), or, when no close is
/// sure, a move above the ball (back to q1, "waiting to close"). The message says why
/// ("re-planned (request 12): the ball at T moved 23.4 mm"); replans() counts them. At most
/// max_replans a grasp and only before max_wait, so the grasp command is still carried out
/// within a bounded wait. A re-plan that came too late (the first CLOSE went out) leaves the hand
/// closed in q1: q1 then opens it (a0) before approaching again. The superseded approach's
/// interaction teaches nothing of the delay (it may have been a motion alone).
///
/// Transitions: the state and activity after the command and the request it makes (sent by
/// take_request()); a refused or ignored command changes nothing but status().message.
///
/// | state activity        | track       | grasp*      | release       | abort         | home     |
/// |-----------------------|-------------|-------------|---------------|---------------|----------|
/// | q0 idle               | q0 tracking | q1 grasping | ignored       | q0 idle STOP  | homing H |
/// | q0 tracking           | q0 tracking | q1 grasping | ignored       | q0 idle STOP  | homing H |
/// | q0 homing             | q0 tracking | q1 grasping | ignored       | q0 idle STOP  | homing   |
/// | q0 backing off        | refused     | refused     | ignored       | q0 idle STOP  | refused  |
/// | q1 grasping (a1 next) | refused     | refused     | ignored       | q0 idle STOP! | refused  |
/// | q2 grasping (a2 sent) | refused     | refused     | ignored       | q0 idle STOP! | refused  |
/// | q3 grasping (a3 next) | refused     | refused     | q0 idle OPEN! | q0 idle STOP! | refused  |
/// | q3 idle               | refused     | refused     | q0 idle OPEN  | q0 idle STOP  | homing H |
/// | q4 grasping (judging) | refused     | refused     | q0 idle OPEN! | q0 idle STOP! | refused  |
/// | q4 idle               | refused     | refused     | q0 idle OPEN  | q0 idle STOP  | homing H |
///
/// At the start: q0 idle, or q3 idle when the first ARM_STATUS reports the gripper CLOSED; no
/// request until a command. grasp*: with a fresh track, otherwise refused; the request is a1,
/// or OPEN (a0) first when the gripper is not reported OPEN. STOP: MODE_STOP + GRIPPER_OPEN;
/// OPEN (a0): MODE_GRIPPER_ONLY + GRIPPER_OPEN, the state turns q0 when it is sent; H: MODE_HOME
/// + GRIPPER_KEEP, the state unchanged. "!": the grasp in progress ends with outcome kAborted. A
/// fresh track is a trajectory that is not lost and not older than max_trajectory_age. Homing ends
/// (activity idle) when HOME is executed.
///
/// The grasp, driven by the arm's answers:
///  - q1 (a1): each take_request() intercepts; the request is MODE_CARTESIAN + GRIPPER_CLOSE and
///    when it is sent the state is q2 (a2, the close, is in flight). Rejected by the arm: back
///    to q1, which tries again.
///  - q2 -> q3 when the arm reports it executed; then a3: straight up by `lift` from the target,
///    same orientation (z clamped to the workspace box).
///  - q3 -> q4 when the lift is executed. The outcome is judged on the measurements captured
///    after the arm reported it had stopped (or kSettleTimeout after the lift, if it never does):
///    success as soon as one puts the ball within success_distance of the arm's tool; failed
///    (the message gives the nearest distance) when none has within judge_time, or "ball not
///    seen after the lift" when none was visible. (The gripper or a panel may hide the held ball
///    for a while, and vision then finds other red things.) Activity idle. (A measurement
///    from before the lift says nothing: the ball sits at the tool whether it was grasped or
///    not.)
///  - Lost track in q1 (the trajectory is lost, or none newer than max_trajectory_age): until
///    max_wait after the grasp command the machine waits for it to return (no request; the arm
///    holds; "waiting to close: no fresh track of the object (3.1 s left)"), as a panel or the
///    gripper can hide the ball longer than the predictor coasts. Then the approach stops; state
///    q0, activity backing off, outcome failed "track lost", and a move straight up by `backoff`
///    from the current tool (orientation by forward kinematics of the current joints); idle when it
///    is executed. In q2 and later the close is already on its way and the track is no longer
///    needed. While tracking, a lost track only stops the requests (and the heartbeats) until it
///    returns.
///  - A lift or back-off rejected by the arm ends the sequence (q3/idle failed, or q0/idle): the
///    same target would be rejected again. A rejected tracking move, approach, open or stop is
///    computed afresh and sent again (after the back-off).
///
/// Requests are made only while ArmView.connected.
///
/// The next one-off request is one value, NextAction, besides the requests that follow the ball
/// (tracking, the approach), which are computed from the state and activity. Its precedence, in
/// take_request() and when a second one is asked for before the first is sent: kStop (abort; sent
/// even with a request in flight) over kOpen (a0: release, a grasp with the hand not reported
/// open, a retry) over the one the activity calls for (kBackoff while backing off, kLift in q3
/// grasping, kHome while homing; these three exclude each other). A higher one asked for hides a
/// lower one; the lower one is taken up again from the activity once the higher is sent (abort,
/// then home: STOP, then HOME; release, then home: OPEN, then HOME). a0 sent in q1 (a grasp
/// asked for with the hand not reported open) leaves q1: the approach follows it.
///
/// Every command is answered (on_command()'s CommandReply): accepted, or refused by the state
/// with the reason (the same text as status().message).
///
/// --no-prediction (use_prediction = false): the path is PredictedPath::hold(last visible
/// measurement) from now on; the track is fresh while that measurement is, or while the
/// trajectories (whose points are otherwise ignored) say the predictor still tracks the ball,
/// e.g. through an occlusion: the baseline aims where the ball was last seen.
///
///     GraspMachine machine(ArmGeometry::a465(), GraspSettings{}, /*first_sequence=*/1);
///     // on each message:                           (now = the shell's clock, us)
///     machine.on_arm_status(view_of(arm_status), now);
///     machine.on_trajectory(path_from(trajectory), trajectory.source_utime, now);
///     CommandReply reply = machine.on_command(GraspCommand::kGrasp, 0.0, now);
///     if (std::optional<ArmRequest> r = machine.take_request(now)) publish(to_arm_cmd(*r));
///     if (machine.arm_need(now) == ArmNeed::kWanted) ... heartbeat every heartbeat_period
///     publish(to_grasp_status(machine.status()));

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "arm_driver/kinematics.hpp"
#include "grasp/interception.hpp"

namespace sg::grasp {

using arm::ArmGeometry;
using arm::Joints;

/// Figure 4's states (grasp_status_t Q*).
enum class GraspState : int8_t {
  kHandOpened = 0,
  kApproaching = 1,
  kGrasping = 2,
  kHandClosed = 3,
  kObjectLifted = 4
};

/// What the machine is doing (grasp_status_t ACTIVITY_*).
enum class GraspActivity : int8_t {
  kIdle = 0,
  kTracking = 1,
  kGrasping = 2,
  kHoming = 3,
  kBackingOff = 4
};

/// Figure 4's actions (grasp_status_t A*), the last one taken.
enum class GraspAction : int8_t {
  kNone = -1,
  kOpenHand = 0,
  kApproachObject = 1,
  kCloseHand = 2,
  kLiftObject = 3
};

/// The outcome of the last grasp (grasp_status_t OUTCOME_*).
enum class GraspOutcome : int8_t { kNone = 0, kSuccess = 1, kFailed = 2, kAborted = 3 };

/// An operator's request (grasp_command_t COMMAND_* values).
enum class GraspCommand : int8_t { kTrack = 1, kGrasp = 2, kRelease = 3, kAbort = 4, kHome = 5 };

/// "q0 hand opened" .. "q4 object lifted".
const char* to_string(GraspState state);
/// "idle", "tracking", "grasping", "homing", "backing off".
const char* to_string(GraspActivity activity);
/// "none", "a0 open hand", "a1 approach object", "a2 close hand", "a3 lift object".
const char* to_string(GraspAction action);
/// "none", "success", "failed", "aborted".
const char* to_string(GraspOutcome outcome);
/// "track", "grasp", "release", "abort", "home" ("unknown" for any other value).
const char* to_string(GraspCommand command);

/// What became of an operator's command (grasp_status_t RESULT_* values). The machine gives
/// kAccepted, kRefusedBadArgument and kRefusedState; the shell (GraspNode) the others.
enum class CommandResult : int8_t {
  kNone = 0,             ///< no command yet
  kAccepted = 1,         ///< taken up (a command that changes nothing, e.g. home while homing)
  kRefusedNotNewer = 2,  ///< its sequence is not newer than its sender's last
  kRefusedUnknownCommand = 3,   ///< not a COMMAND_* value
  kRefusedBadArgument = 4,      ///< e.g. a stand-off outside 0..0.5 m
  kRefusedState = 5,            ///< not in this state (a grasp without a fresh track, ...)
  kRefusedUnauthenticated = 6,  ///< unsigned, a wrong tag, replayed or stale (docs/security.md)
};

/// "none", "accepted", "refused: not newer", "refused: unknown command", "refused: bad
/// argument", "refused: state", "refused: unauthenticated".
const char* to_string(CommandResult result);

/// The machine's answer to a command.
struct CommandReply {
  CommandResult result = CommandResult::kNone;
  std::string reason;  ///< ASCII; why it was refused ("" when accepted)
};

/// The one-off request the machine sends next (besides tracking and the approach), in order of
/// precedence: a later value hides an earlier one, see the file comment.
enum class NextAction : int8_t { kNone, kHome, kLift, kBackoff, kOpen, kStop };

/// What the machine needs of ARM_STATUS.
struct ArmView {
  bool connected = false;  ///< state != DISCONNECTED
  bool moving = false;     ///< state == MOVING
  bool error = false;      ///< state == ERROR (informational: refusals come as rejections)
  int8_t gripper = 0;      ///< arm_status_t::GRIPPER_UNKNOWN / GRIPPER_OPEN / GRIPPER_CLOSED
  int64_t last_received_sequence = -1;
  int64_t last_executed_sequence = -1;
  int64_t last_rejected_sequence = -1;
  std::string rejection_reason;    ///< why last_rejected_sequence was rejected
  int64_t driver_start_utime = 0;  ///< changes when the driver restarts
  std::string watchdog;  ///< the driver watchdog's last stop ("" when none): a change is a stop
  Joints joints = Joints::Zero();
  Eigen::Vector3d tool = Eigen::Vector3d::Zero();  ///< tool centre point
  double interaction_time = 0;                     ///< s, of the driver's last interaction
};

/// One arm_cmd_t to send (the same constants as stereograsp::arm_cmd_t).
struct ArmRequest {
  int64_t sequence = 0;
  int8_t mode = 0;  ///< arm_cmd_t::MODE_CARTESIAN / MODE_GRIPPER_ONLY / MODE_HOME / MODE_STOP
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
  int8_t gripper = 0;  ///< arm_cmd_t::GRIPPER_KEEP / OPEN / CLOSE
  double speed = 0.5;
  int64_t source_utime = 0;  ///< the trajectory's source_utime behind it
  int64_t target_utime = 0;  ///< interception time T (0 when none)
};

/// What sg-grasp accepts on its inputs besides well-formed messages (grasp_messages.hpp
/// check_trajectory): every point inside the arm's workspace widened by `margin`, and times
/// within `max_time_offset` of the receiver's clock.
struct InputGate {
  double margin = 0.25;          ///< m beyond geometry.workspace on every side
  double max_time_offset = 5.0;  ///< s between a message's times and now (0: not checked)
};

struct GraspSettings {
  double standoff = 0.10;           ///< m above the ball while tracking
  double lift = 0.15;               ///< m the object is lifted (a3)
  double backoff = 0.10;            ///< m the tool rises when the track is lost in an approach
  double speed = 0.5;               ///< fraction of the joint speed limits (the paper's 50 %)
  double max_trajectory_age = 1.0;  ///< s: a trajectory older than now - this gives no command
  double success_distance = 0.05;   ///< m: after the lift, a ball this close to the tool = success
  double judge_time = 3.0;      ///< s after the arm stops: no sighting that close by then = failed
  double default_delay = 0.78;  ///< s per controller command until one is measured
  bool use_prediction = true;   ///< false: aim at the last measurement (PredictedPath::hold)
  double heartbeat_period = 0.2;    ///< s between MODE_HEARTBEAT while the arm is wanted
  double resend_after = 0.5;        ///< s: a request ARM_STATUS does not show received is resent
  double arm_status_timeout = 1.0;  ///< s without ARM_STATUS: no request, no heartbeat
  /// When to close (see "Closing when sure" in the file comment).
  double tolerance = 0.02;      ///< m: ball centre to tool centre at the close that still grasps
  double confidence = 2.0;      ///< sigmas of the close's error that must fit in `tolerance`
  double arm_sigma = 0.001;     ///< m, 3D: the arm's and the calibration's error at the tool
  double timing_sigma = 0.035;  ///< s: the spread of the controller's delay (0.72-0.84 s uniform)
  double max_wait = 8.0;        ///< s after the grasp command: then close on the best guess
  /// Re-planning (see the file comment): the newest forecast of the ball at the approach's T
  /// this far from the approach's aim re-plans it ...
  double replan_shift = 0.010;  ///< m
  /// ... while the approach's CLOSE is surely not yet on the line: until one delay less this
  /// after the approach was sent ...
  double replan_margin = 0.15;  ///< s
  int max_replans = 3;          ///< ... at most this many times a grasp
  InterceptionSettings interception;
  InputGate input_gate;
};

/// What the machine asks of the commander lease (arm_cmd_t MODE_HEARTBEAT / MODE_RELEASE).
enum class ArmNeed : int8_t {
  kNone,    ///< not wanted: release the lease (once)
  kWanted,  ///< keep it: a heartbeat every heartbeat_period
  kSilent,  ///< wanted, but no heartbeat (ARM_STATUS silent, or the track followed gone stale):
            ///< the driver's watchdog stops the arm
};

/// "none", "wanted", "silent".
const char* to_string(ArmNeed need);

/// What GRASP_STATUS shows.
struct GraspStatusView {
  GraspState state = GraspState::kHandOpened;
  GraspActivity activity = GraspActivity::kIdle;
  GraspAction last_action = GraspAction::kNone;
  GraspOutcome outcome = GraspOutcome::kNone;
  std::optional<Eigen::Vector3d> target;  ///< current tool target (none after STOP or HOME)
  int64_t target_utime = 0;
  int64_t source_utime = 0;
  std::string message;  ///< why a grasp failed, a target or a command was refused
};

/// The grasp state machine; see the file comment for its transitions.
class GraspMachine {
 public:
  /// A request unanswered this long (or 8 delay estimates, if longer) is treated as rejected.
  static constexpr double kAnswerTimeout = 5.0;  // s
  /// After the lift, the outcome is judged even if the arm still reports moving after this.
  static constexpr double kSettleTimeout = 3.0;  // s
  /// The wait before the retry after the first rejection, doubled for each further one ...
  static constexpr double kRetryFirst = 0.25;  // s
  /// ... up to this.
  static constexpr double kRetryLongest = 4.0;  // s

  /// `first_sequence`: the sequence number of the first request (then +1 per request).
  GraspMachine(ArmGeometry geometry, GraspSettings settings, int64_t first_sequence);

  /// An operator's command at `now`. `standoff` (m) applies to kTrack; 0 keeps the current one,
  /// a negative or non-finite one refuses the command (kRefusedBadArgument). A command the state
  /// refuses (the table's "refused" and "ignored") gives kRefusedState and sets status().message
  /// to the reason.
  CommandReply on_command(GraspCommand command, double standoff, int64_t now);

  /// A new OBJECT_TRAJECTORY (ignored when use_prediction is false).
  void on_trajectory(const PredictedPath& path, int64_t source_utime, int64_t now);

  /// A new OBJECT_POSITION captured at `utime`: nullopt when the ball was not visible.
  void on_measurement(const std::optional<Eigen::Vector3d>& position, int64_t utime);

  /// A new ARM_STATUS: frees the request slot, advances the grasp, learns the delay.
  void on_arm_status(const ArmView& arm, int64_t now);

  /// The next command for the arm, or nullopt. At most one request in flight: a new one only
  /// after the arm reported the previous one executed (or rejected), so each is computed just
  /// before the controller can act on it. Abort is the exception (sent at once). Sequence
  /// numbers increase from first_sequence. A resend returns the request in flight again (the
  /// same sequence and content). Nothing before the first ARM_STATUS, while ARM_STATUS is
  /// silent (but a STOP) or during a back-off after a rejection.
  std::optional<ArmRequest> take_request(int64_t now);

  /// Whether the machine wants the arm at `now` (see ArmNeed and the file comment).
  ArmNeed arm_need(int64_t now) const;

  /// Seconds since the last ARM_STATUS when that is more than arm_status_timeout, else nullopt
  /// (also before the first one).
  std::optional<double> arm_status_silence(int64_t now) const;

  /// The sequence of the last request made (first_sequence - 1 before any).
  int64_t last_sequence() const { return next_sequence_ - 1; }
  /// Requests sent again under the same sequence so far.
  uint64_t resends() const { return resends_; }
  /// Approaches re-planned (see the file comment) since the machine started.
  uint64_t replans() const { return replans_; }
  /// Rejections since the last request the arm executed.
  int consecutive_rejections() const { return rejections_; }
  /// No request but a STOP before this time (the back-off after a rejection; 0: none).
  int64_t retry_utime() const { return retry_utime_; }

  const GraspStatusView& status() const { return status_; }

  /// The one-off request to send next (kNone: only tracking or the approach, if any).
  NextAction next_action() const { return next_; }

  /// Seconds per controller command, learnt from ArmView.interaction_time (an exponential
  /// average, weight kDelayWeight per interaction; an interaction that sent N motion commands
  /// counts as N delays). default_delay until the first one is measured.
  double delay_estimate() const { return delay_; }

  /// Weight of a new measurement in delay_estimate().
  static constexpr double kDelayWeight = 0.3;

 private:
  /// What a request in flight was for.
  enum class Kind { kOpenHand, kStop, kHome, kTrack, kApproach, kLift, kBackoff };

  struct InFlight {
    int64_t sequence = 0;
    Kind kind = Kind::kTrack;
    int64_t sent_utime = 0;    ///< first sent (the answer time-out counts from here)
    int64_t resent_utime = 0;  ///< last sent or resent
    ArmRequest request;        ///< what was sent, for a resend
  };

  /// Commands, one function each; each returns its reply. `where`: " in <state> (<activity>)".
  CommandReply track(double standoff, const std::string& where);
  CommandReply grasp(const std::string& where, int64_t now);
  CommandReply release(const std::string& where);
  CommandReply abort(const std::string& where);
  CommandReply home(const std::string& where);
  /// Refuses a command: status().message and the reply's reason say why.
  CommandReply refuse_command(CommandResult result, std::string reason);

  /// Asks for `action`: it replaces next_ unless next_ has a higher precedence (NextAction order).
  void plan(NextAction action);
  /// The one-off request the activity calls for (after a higher one hid it): kBackoff, kLift,
  /// kHome or kNone.
  NextAction follow_up() const;
  /// One request each, for take_request().
  ArmRequest send_stop(int64_t now);
  ArmRequest send_open(int64_t now);
  ArmRequest send_home(int64_t now);
  std::optional<ArmRequest> send_backoff(int64_t now);
  std::optional<ArmRequest> send_lift(int64_t now);
  std::optional<ArmRequest> send_approach(int64_t now);
  /// In q2, the approach in flight replaced by a new one (or by tracking, back to q1) when
  /// replan_reason() gives a reason.
  std::optional<ArmRequest> replan(int64_t now);
  /// Why the approach in flight should be re-planned at `now` ("" when it should not).
  std::string replan_reason(int64_t now) const;

  /// The path to aim with at `now` (fresh, not lost), with its source_utime, or nullopt.
  std::optional<PredictedPath> fresh_path(int64_t now, int64_t* source_utime) const;
  bool track_fresh(int64_t now) const;
  /// Starts the back-off when the track is lost during q1; outcome judging and time-outs.
  void update(int64_t now);
  void judge(int64_t now);
  /// take_request() but for keeping what it returns whole in in_flight_.
  std::optional<ArmRequest> choose_request(int64_t now);
  /// The request in flight again when ARM_STATUS does not show it received after resend_after.
  std::optional<ArmRequest> resend(int64_t now);
  /// The first ARM_STATUS: q3 when the gripper is reported closed.
  void start_from(const ArmView& arm);
  /// Whether ARM_STATUS shows `sequence` received, executed or rejected.
  bool arm_has(int64_t sequence) const;
  /// A rejection of the request in flight: the back-off and, for a lease, the waiting message.
  void rejected(int64_t now);
  /// While tracking: the message that the track went stale (heartbeats stopped), or its end.
  void note_stale_track(int64_t now);
  /// The request in flight was executed, or failed; `failure` starts the message ("the arm
  /// rejected ", "the arm did not answer ", "driver restarted: abandoned ").
  void answered(bool failed, const std::string& failure, int64_t now);
  /// answered() for each kind whose answer moves the state or the activity; `failure` + what +
  /// `request` is the message when the arm failed it.
  void home_answered(bool failed, const std::string& failure, const std::string& request);
  void approach_answered(bool failed, const std::string& failure, const std::string& request);
  void lift_answered(bool failed, const std::string& failure, const std::string& request,
                     int64_t now);
  void backoff_answered(bool failed, const std::string& failure, const std::string& request);
  void refuse(std::string message);
  void set_message(std::string message);
  /// Ends a grasp in progress with kAborted (abort, release).
  void abort_grasp(const std::string& why);
  bool grasp_in_progress() const;
  /// A tool target check: table plus margin and the workspace box; "" when fine.
  std::string check_target(const Eigen::Vector3d& target) const;
  ArmRequest make(Kind kind, int8_t mode, int8_t gripper, int64_t now);
  std::optional<ArmRequest> cartesian(Kind kind, const Eigen::Vector3d& position,
                                      const Eigen::Vector3d& rpy, int8_t gripper, int64_t now);
  std::optional<ArmRequest> aim(Kind kind, int64_t now);
  /// intercept() for tracking (the stand-off, after_start 0) or the approach (after one delay).
  Interception intercept_for(const PredictedPath& path, bool approach, int64_t now) const;
  /// Whether the approach `aim` may carry the CLOSE now (its motion fits one delay, and
  /// "Closing when sure" above); `note` gets the message either way ("" when nothing to say).
  bool ready_to_close(const PredictedPath& path, const Interception& aim, int64_t now,
                      std::string* note) const;
  /// sigma_close at `t` (m), nullopt when `path` carries no sigmas.
  std::optional<double> close_sigma(const PredictedPath& path, int64_t t) const;

  ArmGeometry geometry_;
  GraspSettings settings_;
  GraspStatusView status_;
  int64_t next_sequence_;
  double delay_;

  int64_t first_sequence_;
  ArmView arm_;
  bool have_arm_ = false;
  int64_t arm_utime_ = 0;  ///< when the last ARM_STATUS arrived
  std::optional<PredictedPath> path_;
  int64_t path_source_utime_ = 0;
  std::optional<Eigen::Vector3d> measured_;  ///< last visible measurement
  int64_t measured_utime_ = 0;
  int64_t grasp_utime_ = 0;  ///< when the grasp in progress was asked for (max_wait)

  std::optional<InFlight> in_flight_;
  std::map<int64_t, int> motion_commands_;  ///< sequence -> motion commands, for the delay
  double seen_interaction_time_ = 0;

  NextAction next_ = NextAction::kNone;  ///< nothing until a command asks
  bool message_is_refusal_ = false;

  uint64_t resends_ = 0;
  uint64_t replans_ = 0;
  int replans_in_grasp_ = 0;
  int rejections_ = 0;              ///< consecutive, reset by an executed request
  int64_t retry_utime_ = 0;         ///< the back-off: no request but a STOP before this
  bool waiting_for_lease_ = false;  ///< the last rejection said another sender commands the arm

  Eigen::Vector3d approach_position_ = Eigen::Vector3d::Zero();  ///< a1's target, for the lift
  Eigen::Vector3d approach_rpy_ = Eigen::Vector3d::Zero();

  bool judging_ = false;
  double nearest_ = 0;        ///< m: the nearest sighting to the tool since the arm came to rest
  int64_t lifted_utime_ = 0;  ///< when the lift was reported executed
  std::optional<int64_t> stopped_utime_;  ///< first status after it with the arm at rest
};

}  // namespace sg::grasp
