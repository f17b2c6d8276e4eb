#include "system/calibration_trial.hpp"

#include <array>
#include <stdexcept>
#include <stop_token>

#include "auth/command_auth.hpp"
#include "auth/lab_key.hpp"
#include "system/simulated_clock.hpp"
#include "vision/dlt.hpp"
#include "vision/stereo_step.hpp"
#include "vision/triangulation.hpp"

namespace sg::system {
namespace {

using stereograsp::arm_cmd_t;
using stereograsp::arm_status_t;

/// sg-calibrate's commander: a heartbeat this often while it holds the lease.
constexpr double kHeartbeatPeriod = 0.2;

/// sg-calibrate's command for a stop (vision/sg_calibrate_main.cpp, command_to).
arm_cmd_t command_to(const vision::ArmTarget& t) {
  arm_cmd_t cmd{};
  cmd.sequence = t.sequence;
  cmd.mode = arm_cmd_t::MODE_CARTESIAN;
  for (int i = 0; i < 3; ++i) cmd.position[i] = t.position[i], cmd.orientation[i] = t.rpy[i];
  cmd.gripper = arm_cmd_t::GRIPPER_KEEP;
  cmd.speed = t.speed;
  return cmd;
}

/// The procedure's world and processes on one clock.
class CalibrationRun {
 public:
  explicit CalibrationRun(const CalibrationTrialParams& p);
  CalibrationTrialResult run();

 private:
  void capture(int64_t index, double t);  // sg-camera-sim + sg-vision (blobs only)
  void driver_loop(double t);             // sg-arm-driver's ARM_STATUS
  void calibrate_loop(double t);          // sg-calibrate's loop
  void on_arm_status(const arm_status_t& s);
  void send(arm_cmd_t command);  // signed, delivered to the driver
  template <class F>
  void deliver(F&& f) {
    clock_.at(clock_.now() + p_.bus_latency, std::forward<F>(f));
  }

  CalibrationTrialParams p_;
  SimulatedClock clock_;
  auth::LabKey key_ = trial_lab_key();
  SimulatedArm arm_;
  sim::CameraSimulator camera_;
  sim::StereoFrame frame_;
  vision::StereoStep vision_;
  vision::RobotCalibration calibration_;
  auth::CommandSigner signer_{key_, "sg-calibrate@trial:3", clock_};
  std::stop_source stop_;
  bool connected_ = false;  // the driver reported the controller idle
  bool holding_lease_ = false;
  int64_t sequence_ = 0;  // the last command's
  double last_sent_ = 0;
  int64_t last_rejected_ = 0;
  std::string error_;
};

CalibrationTrialParams with_ball_in_hand(CalibrationTrialParams p) {
  p.arm.c550.start_holding = true;
  p.calibration.ball_radius = p.sim.ball_radius;
  p.calibration.image_width = p.sim.rig.width;
  p.calibration.image_height = p.sim.rig.height;
  p.sim.frame_rate = p.frame_rate;
  if (!(p.frame_rate > 0) || !(p.bus_latency > 0) || !(p.timeout > 0) ||
      !(p.arm_heard_after >= 0) || !(p.start_after >= 0))
    throw std::invalid_argument("calibration trial: rates and times must be positive");
  return p;
}

CalibrationRun::CalibrationRun(const CalibrationTrialParams& p)
    : p_(with_ball_in_hand(p)),
      clock_(kTrialEpochUtime),
      arm_(p_.arm, clock_, key_,
           [this](double t) -> Eigen::Vector3d {
             return arm_.controller().tool_pose(t).translation();
           }),
      camera_(p_.sim),
      vision_(p_.tracker, cv::Size(p_.sim.rig.width, p_.sim.rig.height), std::nullopt,
              vision::StereoMatchParams{.ball_radius = p_.sim.ball_radius}),
      calibration_(p_.calibration, 1) {}

void CalibrationRun::capture(int64_t index, double t) {
  // sg-camera-sim draws the ball on its scenario path until it hears SIM_ARM_STATE.
  sim::ArmState arm = arm_.state(t);
  arm.present = t >= p_.arm_heard_after;
  camera_.render(index, arm, frame_);
  const vision::StereoOutput out =
      vision_.process(frame_.image[0], frame_.image[1], index, clock_.utime_at(t));
  for (const stereograsp::blob_t& b : out.blob) {
    deliver([this, b](double) {
      calibration_.on_blob(b.camera, b.utime, b.found, {b.centre[0], b.centre[1]}, b.fit_support,
                           b.radius, static_cast<uint64_t>(b.fit_arc));
    });
  }
}

void CalibrationRun::driver_loop(double t) {
  if (auto status = arm_.status_due(t)) deliver([this, s = *status](double) { on_arm_status(s); });
}

/// sg-calibrate's ArmWatch: no command before the controller is connected and idle.
void CalibrationRun::on_arm_status(const arm_status_t& s) {
  if (!connected_) {
    if (s.state != arm_status_t::STATE_IDLE) return;
    connected_ = true;
    last_rejected_ = s.last_rejected_sequence;
  }
  if (s.last_rejected_sequence != last_rejected_) {
    last_rejected_ = s.last_rejected_sequence;
    calibration_.on_arm_rejected(s.last_rejected_sequence, s.rejection_reason);
  }
  if (s.state == arm_status_t::STATE_ERROR || s.state == arm_status_t::STATE_DISCONNECTED) {
    error_ = "the arm reports " + (s.error.empty() ? std::string("an error") : s.error);
    stop_.request_stop();  // thrown after the run, not from inside the driver's wait
  }
  calibration_.on_arm_status(s.utime, s.last_executed_sequence,
                             s.state == arm_status_t::STATE_IDLE);
}

void CalibrationRun::send(arm_cmd_t command) {
  command.utime = clock_.utime();
  signer_.sign("ARM_COMMAND", command);
  last_sent_ = clock_.now();
  deliver([this, command](double) { arm_.on_arm_command(command); });
}

void CalibrationRun::calibrate_loop(double t) {
  if (!connected_ || t < p_.arm_heard_after + p_.start_after) return;
  if (calibration_.done()) {
    arm_cmd_t release{};
    release.sequence = sequence_;
    release.mode = arm_cmd_t::MODE_RELEASE;
    release.gripper = arm_cmd_t::GRIPPER_KEEP;
    send(release);
    stop_.request_stop();
    return;
  }
  if (auto target = calibration_.next_target()) {
    sequence_ = target->sequence;
    holding_lease_ = true;
    send(command_to(*target));
  } else if (holding_lease_ && t - last_sent_ >= kHeartbeatPeriod) {
    arm_cmd_t beat{};
    beat.sequence = sequence_;
    beat.mode = arm_cmd_t::MODE_HEARTBEAT;
    beat.gripper = arm_cmd_t::GRIPPER_KEEP;
    beat.speed = 0.5;
    send(beat);
  }
}

/// m: the RMS 3D error of the calibrated cameras over a 5 x 5 x 5 grid of the calibration box,
/// from the true cameras' exact pixels.
double triangulation_rms(const vision::StereoCalibration& c,
                         const std::array<vision::CameraModel, 2>& truth,
                         const vision::RobotCalibrationParams& box) {
  double sq = 0;
  int n = 0;
  for (int i = 0; i < 125; ++i) {
    const Eigen::Vector3d f(i % 5 / 4.0, i / 5 % 5 / 4.0, i / 25 / 4.0);
    const Eigen::Vector3d x = box.box_min + f.cwiseProduct(box.box_max - box.box_min);
    const auto l = truth[0].project(x), r = truth[1].project(x);
    if (!l || !r) continue;
    const vision::Triangulated t = vision::triangulate({&c.left, &c.right}, {*l, *r});
    sq += (t.position - x).squaredNorm();
    ++n;
  }
  return n > 0 ? std::sqrt(sq / n) : std::nan("");
}

CalibrationTrialResult CalibrationRun::run() {
  clock_.every(1.0 / p_.frame_rate, [this, k = int64_t{0}](double t) mutable { capture(k++, t); });
  clock_.every(kDriverLoopPeriod, [this](double t) { driver_loop(t); });
  clock_.every(0.010, [this](double t) { calibrate_loop(t); });
  clock_.at(p_.timeout, [this](double) { stop_.request_stop(); });
  arm_.run(stop_.get_token());
  if (!error_.empty())
    throw std::runtime_error("calibration trial: " + error_ + " at " + calibration_.progress());
  if (!calibration_.done())
    throw std::runtime_error("calibration trial: not done after " + std::to_string(p_.timeout) +
                             " s at " + calibration_.progress());
  CalibrationTrialResult r;
  try {
    r.solution = calibration_.solve_hand_eye();
  } catch (const vision::CalibrationInputError& e) {
    throw std::runtime_error(std::string("calibration trial: ") + e.what());
  }
  r.solution.cameras.source = "robot-guided calibration in simulated time (calibration trial)";
  r.stop_records = calibration_.stops();
  r.stops = static_cast<int>(r.stop_records.size());
  for (const auto& s : calibration_.stops()) r.skipped += s.skipped;
  r.duration = clock_.now();
  r.triangulation_rms =
      triangulation_rms(r.solution.cameras, sim::make_rig(p_.sim.rig), p_.calibration);
  return r;
}

}  // namespace

CalibrationTrialParams calibration_trial_for(const TrialParams& grasp) {
  CalibrationTrialParams c;
  c.sim = grasp.sim;
  c.tracker = grasp.tracker;
  c.arm = {grasp.arm, grasp.c550, grasp.driver, grasp.baud, grasp.arm_status_rate};
  c.bus_latency = grasp.bus_latency;
  return c;
}

CalibrationTrialResult run_calibration_trial(const CalibrationTrialParams& params) {
  return CalibrationRun(params).run();
}

}  // namespace sg::system
