#include "tests/integration/fault_loop.hpp"

#include <signal.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include "common/clock.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/paper_circle.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
using Cmd = stereograsp::arm_cmd_t;

/// The joints of an "MA j1,...,j6" line (degrees in the line, radians out); nullopt otherwise.
std::optional<arm::Joints> ma_joints(const std::string& command) {
  if (command.rfind("MA ", 0) != 0) return std::nullopt;
  std::istringstream in(command.substr(3));
  arm::Joints q;
  for (int i = 0; i < 6; ++i) {
    std::string field;
    if (!std::getline(in, field, ',')) return std::nullopt;
    q[i] = std::stod(field) * std::numbers::pi / 180.0;
  }
  return q;
}

/// The first word of a RAPL-II command line.
std::string verb(const std::string& command) { return command.substr(0, command.find(' ')); }

}  // namespace

LoopFiles LoopFiles::make() {
  LoopFiles f;
  f.dir = make_temp_dir();
  f.calibration = f.dir + "/cams.yaml";
  f.coefficients = f.dir + "/coeffs.yaml";
  write_circle(f.dir + "/circle.csv");
  EXPECT_EQ(run({program("sg-predictor"), "train", f.dir + "/circle.csv", "--out", f.coefficients})
                .exit_code,
            0);
  EXPECT_EQ(run({program("sg-camera-sim"), "--snapshot", f.dir + "/pair.png", "--calibration-out",
                 f.calibration, "--log-level", "warn"})
                .exit_code,
            0);
  return f;
}

LoopObserver::LoopObserver(Bus& bus) {
  bus.subscribe<stereograsp::arm_status_t>("ARM_STATUS", [this](const auto& m, const auto&) {
    arm_ = m;
    ++arm_statuses_;
    if (m.last_executed_sequence >= 0)
      executed_[m.last_executed_sequence][m.driver_start_utime] = 1;
  });
  bus.subscribe<Cmd>("ARM_COMMAND", [this](const Cmd& m, const ReceiveInfo& info) {
    commands_.push_back({info.recv_utime, m.sender, m.mode, m.sequence});
  });
  bus.subscribe<stereograsp::grasp_status_t>("GRASP_STATUS",
                                             [this](const auto& m, const auto&) { grasp_ = m; });
  bus.subscribe<stereograsp::trajectory_t>("OBJECT_TRAJECTORY",
                                           [this](const auto& m, const auto&) { forecast_ = m; });
  bus.subscribe<stereograsp::point3_t>("GROUND_TRUTH",
                                       [this](const auto& m, const auto&) { ball_ = m; });
  bus.subscribe<stereograsp::sim_arm_state_t>(
      "SIM_ARM_STATE", [this](const stereograsp::sim_arm_state_t& m, const ReceiveInfo& info) {
        // The simulator's own time stamp (the same host's clock): a moment the test was busy
        // elsewhere delays the receipt, not the truth's timeline.
        (void)info;
        sim_.push_back({m.utime, Eigen::Map<const arm::Joints>(m.joints), m.holding_object != 0});
      });
}

bool LoopObserver::tracking_since(int64_t utime) const {
  return forecast_.status == stereograsp::trajectory_t::STATUS_TRACKING &&
         forecast_.source_utime > utime;
}

bool LoopObserver::at_standoff(double standoff) const {
  const double* p = arm_.tool_position;
  return arm_statuses_ > 0 && std::hypot(p[0] - ball_.position[0], p[1] - ball_.position[1],
                                         p[2] - ball_.position[2] - standoff) < 0.03;
}

int64_t LoopObserver::last_command_from(const std::string& prefix, int64_t before) const {
  int64_t last = 0;
  for (const CommandSeen& c : commands_) {
    if (c.recv_utime <= before && c.sender.rfind(prefix, 0) == 0) last = c.recv_utime;
  }
  return last;
}

int LoopObserver::count_commands(const std::string& prefix, int64_t from, int64_t to,
                                 bool motion) const {
  int n = 0;
  for (const CommandSeen& c : commands_) {
    if (c.recv_utime < from || c.recv_utime > to || c.sender.rfind(prefix, 0) != 0) continue;
    if (motion && (c.mode == Cmd::MODE_HEARTBEAT || c.mode == Cmd::MODE_RELEASE)) continue;
    ++n;
  }
  return n;
}

std::optional<int64_t> LoopObserver::at_rest_since(int64_t after, double settled) const {
  if (sim_.empty() || sim_.back().recv_utime <= after) return std::nullopt;
  const arm::Joints& final_joints = sim_.back().joints;
  int64_t since = sim_.back().recv_utime;
  for (auto it = sim_.rbegin(); it != sim_.rend() && it->recv_utime > after; ++it) {
    if ((it->joints - final_joints).cwiseAbs().maxCoeff() > 1e-6) break;
    since = it->recv_utime;
  }
  if (sim_.back().recv_utime - since < static_cast<int64_t>(settled * 1e6)) return std::nullopt;
  return since;
}

std::vector<int64_t> LoopObserver::executed_by_two_drivers() const {
  std::vector<int64_t> twice;
  for (const auto& [sequence, drivers] : executed_) {
    if (drivers.size() > 1) twice.push_back(sequence);
  }
  return twice;
}

CommandAudit audit_commands(const std::string& log_path) {
  const arm::ArmGeometry geometry = arm::ArmGeometry::a465();
  CommandAudit audit;
  std::set<std::string> motions_seen;
  std::ifstream in(log_path);
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string utime, seconds, command;
    if (!std::getline(fields, utime, '\t') || !std::getline(fields, seconds, '\t') ||
        !std::getline(fields, command))
      continue;
    const int64_t t = std::stoll(utime);
    const std::string v = verb(command);
    if (v == "W2" || v == "NOH" || v == "SPEED" || v == "FINISH") continue;  // queries, settings
    audit.acts.push_back(t);
    if (v == "ABORT") audit.aborts.push_back(t);
    if (v == "OPEN") audit.opens.push_back(t);
    if (const std::optional<arm::Joints> q = ma_joints(command)) {
      ++audit.motions;
      if (!motions_seen.insert(command).second) ++audit.repeated_motions;
      const bool inside =
          arm::within_limits(geometry, *q) &&
          geometry.workspace.contains(arm::forward_kinematics(geometry, *q).translation());
      if (!inside) ++audit.outside_limits;
    }
  }
  return audit;
}

FaultLoop::FaultLoop(int port, LoopFiles files, Options options)
    : port_(port),
      files_(std::move(files)),
      options_(std::move(options)),
      url_(test_url(port)),
      dir_(make_temp_dir()),
      bus_(std::make_unique<Bus>(url_)),
      seen_(std::make_unique<LoopObserver>(*bus_)) {}

FaultLoop::~FaultLoop() {
  for (auto& [name, child] : children_) {
    if (child && child->running()) child->signal(SIGINT);
  }
  for (auto& [name, child] : children_) {
    if (child) child->wait(10s);
  }
}

std::vector<std::string> FaultLoop::argv(const std::string& name) const {
  const std::string quiet = "--log-level=warn";
  if (name == "c550") {
    std::vector<std::string> a = {program("sg-c550-sim"), "--lcm-url",      url_,          "--link",
                                  dir_ + "/c550",         "--log-commands", command_log(), quiet};
    a.insert(a.end(), options_.c550_args.begin(), options_.c550_args.end());
    return a;
  }
  if (name == "driver") {
    const char* level = std::getenv("SG_FAULT_DRIVER_LOG_LEVEL");  // e.g. debug, to see why
    return {program("sg-arm-driver"),
            "--lcm-url",
            url_,
            "--device",
            dir_ + "/c550",
            std::string("--log-level=") + (level ? level : "info")};
  }
  if (name == "vision")
    return {program("sg-vision"), "--lcm-url", url_, "--calibration", files_.calibration, quiet};
  if (name == "predictor")
    return {program("sg-predictor"), "--lcm-url",         url_,
            "--coefficients",        files_.coefficients, quiet};
  if (name == "grasp" || name == "grasp2") {
    std::vector<std::string> a = options_.grasp_prefix;
    // A session of seconds: the forecasts stay unsure for 20-30 s, and sg-grasp waits until they
    // are sure before it closes (docs/grasping.md), here up to 30 s.
    for (const std::string& s : {program("sg-grasp"), std::string("--lcm-url"), url_,
                                 std::string("--max-wait"), std::string("30")})
      a.push_back(s);
    a.insert(a.end(), options_.grasp_args.begin(), options_.grasp_args.end());
    return a;
  }
  if (name == "cameras")
    return {program("sg-camera-sim"), "--lcm-url", url_, "--rate", "10", quiet};
  throw std::invalid_argument("no process " + name);
}

void FaultLoop::start(const std::string& name) {
  if (auto it = children_.find(name); it != children_.end() && it->second) {
    if (it->second->running()) kill(name);
  }
  children_[name] = std::make_unique<Child>(argv(name));
  Child& child = *children_[name];
  if (name == "c550") {
    ASSERT_TRUE(sg::test::eventually([&] { return std::filesystem::exists(dir_ + "/c550"); }, 30s,
                                     "sg-c550-sim's pseudo-terminal"));
  } else if (name != "cameras") {
    ASSERT_TRUE(eventually([&] { return !child.running() || joined_bus(child.pid(), port_); }, 60s,
                           name + " to join the bus"));
    ASSERT_TRUE(child.running()) << name << " exited at start\n" << logs();
  }
}

void FaultLoop::start_all() {
  for (const char* name : {"c550", "driver", "vision", "predictor", "grasp"}) {
    start(name);
    if (::testing::Test::HasFatalFailure()) return;
  }
  const int64_t filming = now_utime();
  start("cameras");
  ASSERT_TRUE(eventually(
      [&] {
        return seen_->arm_statuses() > 0 &&
               seen_->arm().state == stereograsp::arm_status_t::STATE_IDLE &&
               seen_->tracking_since(filming);
      },
      60s, "the arm at rest and a forecast of the ball"));
}

int64_t FaultLoop::kill(const std::string& name) {
  Child& child = *children_.at(name);
  const int64_t when = now_utime();
  child.signal(SIGKILL);
  const ProcessResult r = child.wait(10s);
  finished_logs_ += name + " (killed):\n" + r.err + "\n";
  return when;
}

ProcessResult FaultLoop::run_watching(const std::vector<std::string>& argv,
                                      std::chrono::milliseconds timeout) {
  Child child(argv);
  wait_until(
      *bus_, [&] { return !child.running(); }, timeout);
  return child.wait(1s);
}

ProcessResult FaultLoop::grasp_ctl(const std::vector<std::string>& args,
                                   std::chrono::milliseconds timeout) {
  std::vector<std::string> a = {program("sg-grasp-ctl"), "--lcm-url", url_};
  a.insert(a.end(), args.begin(), args.end());
  return run_watching(a, timeout);
}

ProcessResult FaultLoop::arm_ctl(const std::vector<std::string>& args,
                                 std::chrono::milliseconds timeout) {
  std::vector<std::string> a = {program("sg-arm-ctl"), "--lcm-url", url_};
  a.insert(a.end(), args.begin(), args.end());
  return run_watching(a, timeout);
}

bool FaultLoop::track() {
  for (int attempt = 0; attempt < 5; ++attempt) {
    if (grasp_ctl({"track"}, 30s).exit_code == 0) return true;
    watch_for(1s);
  }
  return false;
}

::testing::AssertionResult FaultLoop::eventually(const std::function<bool()>& condition,
                                                 std::chrono::milliseconds deadline,
                                                 const std::string& what) {
  return sg::test::eventually(*bus_, condition, deadline, what);
}

void FaultLoop::watch_for(std::chrono::milliseconds duration) { handle_for(*bus_, duration); }

std::string FaultLoop::logs() {
  std::string out = finished_logs_;
  for (auto& [name, child] : children_) {
    if (!child) continue;
    const std::string err = read_text(child->err_path());
    out += name + " (pid " + std::to_string(child->pid()) + ", running " +
           (child->running() ? "yes" : "no") + "), the end of its stderr:\n" +
           err.substr(err.size() > 3000 ? err.size() - 3000 : 0) + "\n";
  }
  return out;
}

pid_t FaultLoop::pid(const std::string& name) const { return children_.at(name)->pid(); }

}  // namespace sg::test
