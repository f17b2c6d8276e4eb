#include "system/grasp_trial.hpp"

#include <optional>
#include <random>
#include <stdexcept>
#include <stop_token>
#include <vector>

#include "auth/command_auth.hpp"
#include "auth/lab_key.hpp"
#include "common/change_or_period.hpp"
#include "grasp/grasp_node.hpp"
#include "predictor/trajectory_message.hpp"
#include "sim/c550_emulator.hpp"
#include "sim/occlusion.hpp"
#include "sim/stereo_rig.hpp"
#include "stereograsp/grasp_command_t.hpp"
#include "system/simulated_arm.hpp"
#include "system/simulated_clock.hpp"
#include "vision/stereo_step.hpp"

namespace sg::system {
namespace {

using stereograsp::arm_cmd_t;
using stereograsp::point3_t;

/// sg-grasp's loop handles the bus for 10 ms, then polls the node.
constexpr double kGraspLoopPeriod = 0.010;
/// A message as its subscribers receive it: encoded and decoded as on the bus.
template <class T>
T over_bus(const T& message) {
  std::vector<uint8_t> bytes(static_cast<size_t>(message.getEncodedSize()));
  if (message.encode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0)
    throw std::logic_error("a trial message does not encode");
  T received;
  if (received.decode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0)
    throw std::logic_error("a trial message does not decode");
  return received;
}

void check(const TrialParams& p) {
  if (!(p.frame_rate > 0) || !(p.arm_status_rate > 0) || !(p.grasp_status_rate > 0) ||
      !(p.timeout > 0) || !(p.bus_latency > 0) || !(p.pixel_sigma >= 0) || !(p.grasp_time >= 0))
    throw std::invalid_argument("grasp trial: rates, times and latencies must be positive");
}

/// The world, the five processes' cores, and the wiring between them on one clock.
class Trial {
 public:
  explicit Trial(const TrialParams& p);
  TrialResult run();

 private:
  // ---- The world ----
  Eigen::Vector3d ball_at(double t) const;
  /// One stereo frame through the cameras and sg-vision: OBJECT_POSITION, or none without a
  /// calibration.
  point3_t see(int64_t index, double t);
  point3_t model_camera(double t, const Eigen::Vector3d& truth);

  // ---- The processes ----
  void capture(int64_t index, double t);            // sg-camera-sim + sg-vision
  void on_position(const point3_t& position);       // sg-predictor, and sg-grasp's subscription
  void grasp_loop(double t);                        // sg-grasp's loop
  void driver_loop(double t);                       // sg-arm-driver's loop
  void operator_command(int8_t command, double t);  // sg-grasp-ctl
  void send_arm_command(arm_cmd_t command);         // sg-grasp's signed publish
  template <class F>
  void deliver(F&& f) {
    clock_.at(clock_.now() + p_.bus_latency, std::forward<F>(f));
  }

  void record_close();
  TrialResult finish();

  TrialParams p_;
  SimulatedClock clock_;
  std::unique_ptr<sim::Scenario> scenario_;
  std::array<vision::CameraModel, 2> cameras_;
  std::unique_ptr<sim::CameraSimulator> camera_;
  sim::StereoFrame frame_;
  std::mt19937_64 noise_rng_;
  auth::LabKey key_ = trial_lab_key();
  SimulatedArm arm_;  // the C550 on its line, sg-arm-driver's core
  vision::StereoStep vision_;
  predictor::TrajectoryPredictor predictor_;
  grasp::GraspNode node_;
  auth::CommandSigner grasp_signer_{key_, "sg-grasp@trial:1", clock_};
  auth::CommandSigner operator_signer_{key_, "sg-grasp-ctl@trial:2", clock_};
  std::stop_source stop_;

  int64_t operator_sequence_ = 0;
  std::optional<arm_cmd_t> close_command_;  ///< the last ARM_COMMAND that closes the hand
  int64_t last_rejected_ = -1;
  double last_seen_ = std::nan("");
  double vision_sq_ = 0;
  int vision_n_ = 0;
  bool outcome_seen_ = false;
  TrialResult result_;
};

/// The cameras sg-vision triangulates with: the trial's calibration, or the simulator's own.
vision::StereoCalibration vision_calibration(const TrialParams& p,
                                             const std::array<vision::CameraModel, 2>& cameras) {
  if (p.calibration) return *p.calibration;
  vision::StereoCalibration c;
  c.left = cameras[0];
  c.right = cameras[1];
  c.source = "grasp trial: the simulator's true cameras";
  return c;
}

SimulatedArmParams arm_params(const TrialParams& p) {
  return {p.arm, p.c550, p.driver, p.baud, p.arm_status_rate};
}

Trial::Trial(const TrialParams& p)
    : p_((check(p), p)),
      clock_(kTrialEpochUtime),
      scenario_(sim::make_scenario(p.sim.scenario)),
      cameras_(sim::make_rig(p.sim.rig)),
      noise_rng_(p.seed * 0x9E3779B97F4A7C15ULL + 17),
      arm_(arm_params(p), clock_, key_, [this](double t) { return ball_at(t); }),
      vision_(p.tracker, cv::Size(p.sim.rig.width, p.sim.rig.height),
              vision_calibration(p, cameras_),
              vision::StereoMatchParams{.ball_radius = p.sim.ball_radius}),
      predictor_(p.predictor),
      node_(p.arm, p.grasp, kTrialEpochUtime, 1.0 / p.grasp_status_rate) {
  p_.sim.frame_rate = p.frame_rate;
  node_.require_signed_commands(key_, "GRASP_COMMAND");
  if (p_.render) camera_ = std::make_unique<sim::CameraSimulator>(p_.sim);
}

Eigen::Vector3d Trial::ball_at(double t) const {
  const sim::C550Controller& c = arm_.controller();
  if (c.holding()) return c.tool_pose(t).translation();
  if (c.released_at()) return *c.released_at();  // stays where let go
  return scenario_->position(t);
}

point3_t Trial::model_camera(double t, const Eigen::Vector3d& truth) {
  std::array<vision::Observation, 2> o;
  std::normal_distribution<double> noise(0.0, p_.pixel_sigma);
  for (size_t i = 0; i < 2; ++i) {
    const auto px = cameras_[i].project(truth);
    o[i].found = px && !sim::fully_occluded_at(p_.sim.occlusion, t);
    if (o[i].found) {
      o[i].blob.centroid = {px->x() + noise(noise_rng_), px->y() + noise(noise_rng_)};
      o[i].centre = o[i].blob.centroid;
    }
  }
  return vision::position_of(o, *vision_.calibration(), clock_.utime_at(t));
}

point3_t Trial::see(int64_t index, double t) {
  if (!camera_) return model_camera(t, ball_at(t));
  camera_->render(index, arm_.state(t), frame_);
  return *vision_.process(frame_.image[0], frame_.image[1], index, clock_.utime_at(t)).position;
}

void Trial::capture(int64_t index, double t) {
  ++result_.frames;
  const Eigen::Vector3d truth = camera_ ? Eigen::Vector3d::Zero() : ball_at(t);
  const point3_t position = see(index, t);
  const Eigen::Vector3d seen_truth = camera_ ? frame_.ball : truth;
  if (position.visible) {
    ++result_.visible;
    if (arm_.controller().closes().empty()) last_seen_ = t;  // the last sighting before the CLOSE
    if (!arm_.controller().holding()) {
      const Eigen::Vector3d m(position.position[0], position.position[1], position.position[2]);
      vision_sq_ += (m - seen_truth).squaredNorm();
      ++vision_n_;
    }
  }
  deliver([this, m = over_bus(position)](double) { on_position(m); });
}

void Trial::on_position(const point3_t& position) {
  node_.on_position(position);
  for (const predictor::Forecast& f : predictor_.add(predictor::measurement_of(position))) {
    ++result_.trajectories;
    deliver([this, m = over_bus(predictor::to_trajectory_t(f, p_.predictor))](double) {
      node_.on_trajectory(m, clock_.utime());
    });
  }
}

void Trial::grasp_loop(double) {
  const grasp::GraspNode::Output out = node_.poll(clock_.utime());
  if (out.lease) send_arm_command(*out.lease);  // MODE_HEARTBEAT / MODE_RELEASE
  if (!out.arm_command) return;
  ++result_.requests;
  if (out.arm_command->gripper == arm_cmd_t::GRIPPER_CLOSE) {
    close_command_ = out.arm_command;
    result_.approach_message = node_.machine().status().message;
  }
  send_arm_command(*out.arm_command);
}

void Trial::send_arm_command(arm_cmd_t command) {
  grasp_signer_.sign("ARM_COMMAND", command);
  deliver([this, m = over_bus(command)](double) { arm_.on_arm_command(m); });
}

void Trial::driver_loop(double t) {
  std::optional<stereograsp::arm_status_t> due = arm_.status_due(t);
  if (!due) return;
  const stereograsp::arm_status_t& status = *due;
  if (status.last_rejected_sequence != last_rejected_) {
    last_rejected_ = status.last_rejected_sequence;
    ++result_.rejected;
    result_.arm_rejection = status.rejection_reason;
  }
  deliver([this, m = over_bus(status)](double) { node_.on_arm_status(m, clock_.utime()); });
}

void Trial::operator_command(int8_t command, double t) {
  stereograsp::grasp_command_t c{};
  c.utime = clock_.utime_at(t);
  c.sequence = ++operator_sequence_;
  c.command = command;
  c.standoff = 0;  // sg-grasp's own
  operator_signer_.sign("GRASP_COMMAND", c);
  deliver([this, m = over_bus(c)](double) {
    const grasp::CommandRecord& answer = node_.on_command(m, clock_.utime());
    if (m.command == stereograsp::grasp_command_t::COMMAND_GRASP &&
        answer.reply.result != grasp::CommandResult::kAccepted) {
      result_.refused = true;
      stop_.request_stop();
    }
  });
}

TrialResult Trial::run() {
  result_.grasp_time = p_.grasp_time;
  clock_.every(1.0 / p_.frame_rate, [this, k = int64_t{0}](double t) mutable { capture(k++, t); });
  clock_.every(kGraspLoopPeriod, [this](double t) {
    grasp_loop(t);
    if (!outcome_seen_ && node_.machine().status().outcome != grasp::GraspOutcome::kNone &&
        clock_.now() > p_.grasp_time) {
      outcome_seen_ = true;
      clock_.at(t + p_.settle_after_outcome, [this](double) { stop_.request_stop(); });
    }
  });
  clock_.every(kDriverLoopPeriod, [this](double t) { driver_loop(t); });
  operator_command(stereograsp::grasp_command_t::COMMAND_TRACK, 0.0);
  clock_.at(p_.grasp_time,
            [this](double t) { operator_command(stereograsp::grasp_command_t::COMMAND_GRASP, t); });
  clock_.at(p_.grasp_time + p_.timeout, [this](double) { stop_.request_stop(); });
  arm_.run(stop_.get_token());  // every wait of the driver runs the world
  return finish();
}

void Trial::record_close() {
  const sim::C550Controller& controller = arm_.controller();
  const auto& closes = controller.closes();
  if (closes.empty()) return;
  const sim::C550Controller::CloseRecord& c = closes.front();
  const Eigen::Vector3d ball = c.ball.value_or(Eigen::Vector3d::Constant(std::nan("")));
  result_.closed = true;
  result_.close_time = c.t;
  result_.miss_distance = (c.tcp - ball).norm();
  result_.track_age = c.t - last_seen_;
  if (close_command_) {
    const Eigen::Vector3d aim(close_command_->position[0], close_command_->position[1],
                              close_command_->position[2]);
    result_.aim_error = (aim - ball).norm();
    if (close_command_->target_utime != 0)
      result_.timing_error = c.t - clock_.time_of(close_command_->target_utime);
  }
  const double rise = controller.tool_pose(clock_.now()).translation().z() - c.tcp.z();
  result_.lifted = controller.holding() && rise >= 0.5 * p_.grasp.lift;
}

TrialResult Trial::finish() {
  record_close();
  const grasp::GraspStatusView& s = node_.machine().status();
  result_.end_time = clock_.now();
  result_.outcome = s.outcome;
  result_.final_state = s.state;
  result_.message = s.message;
  result_.success = arm_.controller().holding() && result_.lifted;
  result_.machine_success = s.outcome == grasp::GraspOutcome::kSuccess;
  result_.machine_agrees = result_.machine_success == result_.success;
  for (const std::string& line : arm_.emulator().executed_commands()) {
    const std::string verb = line.substr(0, line.find(' '));
    if (verb == "MA" || verb == "READY" || verb == "OPEN" || verb == "CLOSE" || verb == "ABORT")
      ++result_.interactions;
  }
  result_.serial_bytes = arm_.line().bytes_written();
  result_.replans = static_cast<int>(node_.machine().replans());
  result_.gripper_actions_dropped = static_cast<int>(arm_.driver().gripper_actions_dropped());
  if (vision_n_ > 0) result_.vision_rms = std::sqrt(vision_sq_ / vision_n_);
  result_.vision_samples = static_cast<int64_t>(vision_n_);
  return result_;
}

}  // namespace

TrialParams paper_trial(uint64_t seed) {
  TrialParams p;
  p.seed = seed;
  p.sim.scenario.kind = "paper";
  p.sim.scenario.seed = seed;
  p.sim.scene.seed = seed;
  p.c550.seed = static_cast<uint32_t>(seed * 2654435761ULL + 1);
  return p;
}

TrialResult run_grasp_trial(const TrialParams& params) { return Trial(params).run(); }

}  // namespace sg::system
