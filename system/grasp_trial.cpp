#include "system/grasp_trial.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>

#include "arm_driver/command_validator.hpp"
#include "grasp/grasp_messages.hpp"
#include "vision/triangulation.hpp"

namespace sg::system {
using namespace sg::sim;  // NOLINT: the trial is rewritten on the product's parts
namespace {

using Cmd = stereograsp::arm_cmd_t;
constexpr double kNever = std::numeric_limits<double>::infinity();

int64_t utime_at(double t) { return kTrialEpochUtime + std::llround(t * 1e6); }
double time_of(int64_t utime) { return static_cast<double>(utime - kTrialEpochUtime) * 1e-6; }

/// One controller action of an interaction, in the order sg-arm-driver sends them.
enum class Step { kMove, kReady, kAbort, kOpen, kClose };

/// A trial: the world (ball, controller), the driver model, vision, predictor and machine.
class Trial {
 public:
  explicit Trial(const TrialParams& p)
      : p_(p),
        controller_(p.arm, p.c550),
        validator_(p.arm),
        machine_(p.arm, p.grasp, 1),
        predictor_(p.predictor),
        noise_rng_(p.seed * 0x9E3779B97F4A7C15ULL + 17) {
    if (!(p.frame_rate > 0) || !(p.status_rate > 0) || !(p.timeout > 0) || !(p.w2_time >= 0) ||
        !(p.bus_latency > 0))
      throw std::invalid_argument("grasp trial: rates, timeout and latencies must be positive");
    p_.sim.frame_rate = p.frame_rate;
    scenario_ = make_scenario(p_.sim.scenario);
    if (p_.render) {
      camera_ = std::make_unique<CameraSimulator>(p_.sim);
      const cv::Size size(p_.sim.rig.width, p_.sim.rig.height);
      trackers_.emplace_back(p_.tracker, size);
      trackers_.emplace_back(p_.tracker, size);
    }
    polled_ = controller_.joints(0);
    view_.connected = true;
    set_view_joints();
  }

  TrialResult run() {
    result_.grasp_time = p_.grasp_time;
    machine_.on_command(grasp::GraspCommand::kTrack, 0.0, utime_at(0));
    pump(0);
    int64_t frame = 0, tick = 0, shell = 0;
    bool grasp_sent = false;
    double stop_at = p_.grasp_time + p_.timeout;
    for (;;) {
      const double t_frame = static_cast<double>(frame) / p_.frame_rate;
      const double t_tick = static_cast<double>(tick) / p_.status_rate;
      const double t_shell = static_cast<double>(shell) * kShellPeriod;
      const double t_grasp = grasp_sent ? kNever : p_.grasp_time;
      const double t_poll = current_ ? kNever : next_poll_;
      const double t = std::min(
          {step_time_, end_time_, t_poll, change_at_, t_tick, t_frame, t_grasp, t_shell, stop_at});
      if (t >= stop_at) {
        now_ = stop_at;
        break;
      }
      now_ = t;
      if (step_time_ <= t) execute_step(t);
      if (end_time_ <= t) finish_interaction(t);
      if (!current_ && next_poll_ <= t) poll(t);
      if (change_at_ <= t) deliver_status(t);
      if (t_tick <= t) deliver_status(t), ++tick;
      if (t_frame <= t) capture(frame++, t);
      if (t_grasp <= t) {
        grasp_sent = true;
        machine_.on_command(grasp::GraspCommand::kGrasp, 0.0, utime_at(t));
        if (machine_.status().activity != grasp::GraspActivity::kGrasping) {
          result_.refused = true;
          break;
        }
      }
      if (t_shell <= t) ++shell;
      pump(t);
      if (grasp_sent && !outcome_seen_ && machine_.status().outcome != grasp::GraspOutcome::kNone) {
        outcome_seen_ = true;
        stop_at = std::min(stop_at, t + p_.settle_after_outcome);
      }
    }
    return finish();
  }

 private:
  /// sg-grasp asks the machine for a request every 10 ms.
  static constexpr double kShellPeriod = 0.01;

  // ---- The world ----

  /// The ball's true centre at t: on its path, in the gripper, or where it was let go.
  Eigen::Vector3d ball_at(double t) const {
    if (controller_.holding()) return controller_.tool_pose(t).translation();
    if (dropped_at_) return *dropped_at_;
    return scenario_->position(t);
  }

  ArmState arm_state(double t) const {
    ArmState a;
    a.present = true;
    const Eigen::Isometry3d tool = controller_.tool_pose(t);
    a.tool_position = tool.translation();
    a.tool_rpy = arm::rpy_from_rotation(tool.rotation());
    a.gripper_opening = controller_.gripper_opening(t);
    a.holding_object = controller_.holding();
    return a;
  }

  /// A stereo frame: rendered and measured by the vision library, or truth plus noise.
  void capture(int64_t index, double t) {
    ++result_.frames;
    std::optional<Eigen::Vector3d> measured;
    Eigen::Vector3d truth;
    if (camera_) {
      camera_->render(index, arm_state(t), frame_);
      truth = frame_.ball;
      vision::Observation o[2];
      for (int i = 0; i < 2; ++i) o[i] = trackers_[static_cast<size_t>(i)].track(frame_.image[i]);
      if (o[0].found && o[1].found) {  // as sg-vision: OBJECT_POSITION visible when both see it
        const auto tri = vision::triangulate({&camera_->camera(0), &camera_->camera(1)},
                                             {{o[0].blob.centroid.x, o[0].blob.centroid.y},
                                              {o[1].blob.centroid.x, o[1].blob.centroid.y}});
        if (tri.position.allFinite()) measured = tri.position;
      }
    } else {
      truth = ball_at(t);
      if (!fully_occluded_at(p_.sim.occlusion, t)) {
        std::normal_distribution<double> n(0.0, p_.vision_sigma);
        measured = truth + Eigen::Vector3d(n(noise_rng_), n(noise_rng_), n(noise_rng_));
      }
    }
    const int64_t utime = utime_at(t);
    if (measured) {
      ++result_.visible;
      last_seen_ = t;
      if (!controller_.holding()) {
        vision_sq_ += (*measured - truth).squaredNorm();
        ++vision_n_;
      }
    }
    machine_.on_measurement(measured, utime);
    pump(t);
    const predictor::Measurement m{utime, measured.has_value(),
                                   measured.value_or(Eigen::Vector3d::Zero())};
    for (const predictor::Forecast& f : predictor_.add(m)) {
      grasp::PredictedPath path;
      path.utime = f.utime;
      path.start_utime = f.utime + f.period_us;
      path.period_us = f.period_us;
      path.points = f.positions;
      path.lost = f.status == predictor::TrackStatus::kLost;
      ++result_.trajectories;
      machine_.on_trajectory(path, f.source_utime, utime);
      pump(t);
    }
  }

  // ---- sg-grasp's shell ----

  void pump(double t) {
    for (int i = 0; i < 4; ++i) {  // one request in flight (abort aside): never more than a few
      std::optional<grasp::ArmRequest> r = machine_.take_request(utime_at(t));
      if (!r) return;
      submit(*r, t);
    }
  }

  void deliver_status(double t) {
    if (change_at_ <= t) change_at_ = kNever;
    machine_.on_arm_status(view_, utime_at(t));
  }

  /// ARM_STATUS is also sent on every change; it reaches the machine a bus hop later.
  void status_changed(double t) { change_at_ = std::min(change_at_, t + p_.bus_latency); }

  // ---- sg-arm-driver ----

  void set_view_joints() {
    view_.joints = polled_;
    view_.tool = arm::forward_kinematics(p_.arm, polled_).translation();
  }

  /// The driver's W2: the joints, and whether the arm is still on its way to the commanded ones.
  void read_joints(double t) {
    polled_ = controller_.joints(t);
    set_view_joints();
    const bool moving =
        commanded_ && (polled_ - *commanded_).cwiseAbs().maxCoeff() > kArrivedTolerance;
    if (!view_.error) view_.moving = moving;
    next_poll_ = t + (moving ? 0.1 : 0.5);
  }

  void poll(double t) { read_joints(t); }

  /// A request from the machine: validated on arrival, then the latest-wins slot.
  void submit(const grasp::ArmRequest& r, double t) {
    ++result_.requests;
    const Cmd c = grasp::to_arm_cmd(r, utime_at(t));
    const arm::Joints reference =
        pending_ && pending_->moves_arm() ? pending_->joints : commanded_.value_or(polled_);
    arm::ValidationResult v = validator_.validate(c, reference);
    if (!v.target) {
      ++result_.rejected;
      view_.last_rejected_sequence = r.sequence;
      result_.arm_rejection = v.reason;
      status_changed(t);
      return;
    }
    requests_[r.sequence] = r;
    pending_ = std::move(v.target);
    if (!current_) start_next(t);
    status_changed(t);
  }

  void start_next(double t) {
    if (!pending_) return;
    current_ = std::move(pending_);
    pending_.reset();
    ++result_.interactions;
    interaction_start_ = t;
    controller_error_.clear();
    view_.moving = true;  // the driver's state is MOVING for the whole interaction
    view_.error = false;
    const int percent = std::clamp(static_cast<int>(std::lround(current_->speed * 100)), 1, 100);
    if (current_->mode != Cmd::MODE_STOP && percent != speed_percent_) {
      (void)controller_.set_speed(percent);  // SPEED does not wait for the delay
      speed_percent_ = percent;
    }
    steps_.clear();
    if (current_->mode == Cmd::MODE_STOP) {
      steps_.push_back(Step::kAbort);  // the driver sends ABORT alone
    } else {
      if (current_->moves_arm()) steps_.push_back(Step::kMove);
      if (current_->mode == Cmd::MODE_HOME) steps_.push_back(Step::kReady);
      if (current_->gripper == Cmd::GRIPPER_OPEN) steps_.push_back(Step::kOpen);
      if (current_->gripper == Cmd::GRIPPER_CLOSE) steps_.push_back(Step::kClose);
    }
    next_step_ = 0;
    schedule_step(t);
    status_changed(t);
  }

  /// Motion commands act one interaction delay after they are sent; ABORT at once.
  void schedule_step(double t) {
    if (next_step_ >= steps_.size()) {
      step_time_ = kNever;
      end_time_ = t + p_.w2_time;
      return;
    }
    step_time_ = steps_[next_step_] == Step::kAbort ? t : t + controller_.interaction_delay();
  }

  void execute_step(double t) {
    const Step step = steps_[next_step_++];
    CommandResult r;
    switch (step) {
      case Step::kMove:
        if (result_.closed && controller_.holding()) result_.lifted = true;
        r = controller_.move_joints(current_->joints, t);
        if (!r) result_.lifted = false;
        break;
      case Step::kReady:
        r = controller_.ready(t);
        break;
      case Step::kAbort:
        controller_.abort(t);
        break;
      case Step::kOpen:
        if (controller_.holding()) dropped_at_ = controller_.tool_pose(t).translation();
        controller_.open(t);
        break;
      case Step::kClose:
        record_close(t);
        break;
    }
    if (!r) {  // the controller refused: the driver sends nothing more of this command
      controller_error_ = "controller: " + r.error;
      next_step_ = steps_.size();
    }
    schedule_step(t);
  }

  void record_close(double t) {
    const Eigen::Vector3d ball = ball_at(t);
    if (!result_.closed) {
      result_.closed = true;
      result_.close_time = t;
      result_.miss_distance = (controller_.tool_pose(t).translation() - ball).norm();
      result_.track_age = t - last_seen_;
      if (auto it = requests_.find(current_->sequence); it != requests_.end()) {
        result_.aim_error = (it->second.position - ball).norm();
        if (it->second.target_utime != 0)
          result_.timing_error = t - time_of(it->second.target_utime);
      }
    }
    controller_.close(t, ball);
  }

  void finish_interaction(double t) {
    end_time_ = kNever;
    const arm::ArmTarget& target = *current_;
    view_.last_executed_sequence = target.sequence;
    if (!controller_error_.empty()) {
      ++result_.rejected;
      view_.last_rejected_sequence = target.sequence;
      view_.error = true;
      view_.moving = false;
      result_.arm_rejection = controller_error_;
    } else {
      view_.error = false;
      if (target.mode == Cmd::MODE_STOP || target.mode == Cmd::MODE_HOME) commanded_.reset();
      if (target.moves_arm()) commanded_ = target.joints;
    }
    read_joints(t);
    view_.interaction_time = t - interaction_start_;
    current_.reset();
    status_changed(t);
    start_next(t);
  }

  TrialResult finish() {
    const grasp::GraspStatusView& s = machine_.status();
    result_.end_time = now_;
    result_.outcome = s.outcome;
    result_.final_state = s.state;
    result_.message = s.message;
    result_.success = controller_.holding() && result_.lifted;
    result_.machine_success = s.outcome == grasp::GraspOutcome::kSuccess;
    result_.machine_agrees = result_.machine_success == result_.success;
    if (vision_n_ > 0) result_.vision_rms = std::sqrt(vision_sq_ / vision_n_);
    return result_;
  }

  static constexpr double kArrivedTolerance = 1e-3;  // rad, DriverSettings::arrived_tolerance

  TrialParams p_;
  std::unique_ptr<Scenario> scenario_;
  std::unique_ptr<CameraSimulator> camera_;
  std::vector<vision::BlobTracker> trackers_;
  StereoFrame frame_;
  C550Controller controller_;
  arm::CommandValidator validator_;
  grasp::GraspMachine machine_;
  predictor::TrajectoryPredictor predictor_;
  std::mt19937_64 noise_rng_;
  std::optional<Eigen::Vector3d> dropped_at_;

  // The driver model.
  grasp::ArmView view_;
  arm::Joints polled_ = arm::Joints::Zero();
  std::optional<arm::Joints> commanded_;
  std::optional<arm::ArmTarget> pending_;
  std::optional<arm::ArmTarget> current_;
  std::vector<Step> steps_;
  size_t next_step_ = 0;
  std::string controller_error_;
  int speed_percent_ = -1;
  double interaction_start_ = 0;
  double step_time_ = kNever;
  double end_time_ = kNever;
  double next_poll_ = 0;
  double change_at_ = kNever;
  std::map<int64_t, grasp::ArmRequest> requests_;

  double now_ = 0;
  double last_seen_ = std::nan("");
  bool outcome_seen_ = false;
  double vision_sq_ = 0;
  int vision_n_ = 0;
  TrialResult result_;
};

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
