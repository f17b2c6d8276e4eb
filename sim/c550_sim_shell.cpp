#include "sim/c550_sim_shell.hpp"

#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "arm_driver/kinematics.hpp"
#include "common/clock.hpp"
#include "common/shutdown.hpp"
#include "stereograsp/point3_t.hpp"

namespace sg::sim {
namespace {

std::string system_error(const std::string& what) { return what + ": " + std::strerror(errno); }

}  // namespace

stereograsp::sim_arm_state_t arm_state_message(const C550Controller& c550, double t,
                                               int64_t utime) {
  stereograsp::sim_arm_state_t m{};
  m.utime = utime;
  const sg::arm::Joints q = c550.joints(t);
  const Eigen::Isometry3d pose = sg::arm::forward_kinematics(c550.geometry(), q);
  const Eigen::Vector3d rpy = sg::arm::rpy_from_rotation(pose.rotation());
  for (int i = 0; i < 6; ++i) m.joints[i] = q[i];
  for (int i = 0; i < 3; ++i) {
    m.tool_position[i] = pose.translation()[i];
    m.tool_orientation[i] = rpy[i];
  }
  m.gripper_opening = c550.gripper_opening(t);
  m.holding_object = c550.holding();
  return m;
}

C550SimShell::C550SimShell(const C550SimSettings& settings, C550Controller& controller, Bus& bus)
    : s_(settings),
      controller_(controller),
      bus_(bus),
      link_(settings.link),
      faults_(settings.faults.garble_rate, settings.faults.drop_ack_rate,
              settings.controller.seed ^ 0x5eedu) {
  if (!s_.log_commands.empty()) {
    log_.open(s_.log_commands, std::ios::app);
    if (!log_) throw std::runtime_error("--log-commands " + s_.log_commands + ": cannot append");
  }
  bus_.subscribe<stereograsp::point3_t>(
      "GROUND_TRUTH", [this](const stereograsp::point3_t& p, const ReceiveInfo&) {
        ball_.add(p.utime, Eigen::Vector3d(p.position[0], p.position[1], p.position[2]));
      });
}

int C550SimShell::run() {
  connect();
  double next_state = 0;
  while (!shutdown_requested()) {
    const double t = now();
    schedule_line(t);
    if (t >= next_state) {
      bus_.publish("SIM_ARM_STATE", arm_state_message(controller_, t, now_utime()));
      next_state += 1.0 / s_.state_rate;
      if (next_state < t) next_state = t + 1.0 / s_.state_rate;  // fell behind: skip ahead
    }
    wait(std::min(next_state, next_event()) - now());
    serve(now());
  }
  spdlog::info("stopping: {} bytes garbled, {} ACKs dropped", faults_.garbled(), faults_.dropped());
  return 0;
}

double C550SimShell::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void C550SimShell::connect() {
  pty_ = std::make_unique<PseudoTerminal>();
  emulator_ = std::make_unique<C550Emulator>(controller_, s_.slave);
  emulator_->set_ball_centre(ball_.at(now_utime()));
  logged_ = 0;
  tx_.clear();
  link_.point_to(pty_->path());
  std::printf("sg-c550-sim: serial device %s\n", pty_->path().c_str());
  std::fflush(stdout);
}

void C550SimShell::schedule_line(double t) {
  const LineFaults& f = s_.faults;
  if (pty_ && !disconnected_ && f.disconnect_after > 0 && t >= f.disconnect_after) {
    spdlog::info("disconnecting {} (--disconnect-after {} s)", pty_->path(), f.disconnect_after);
    disconnected_ = true;
    link_.remove();
    emulator_.reset();
    pty_.reset();
    reconnect_at_ = t + f.reconnect_after;
  } else if (!pty_ && t >= reconnect_at_) {
    connect();
  }
}

double C550SimShell::next_event() const {
  double next = std::numeric_limits<double>::infinity();
  if (emulator_) next = emulator_->next_output_time();
  if (pty_ && !disconnected_ && s_.faults.disconnect_after > 0)
    next = std::min(next, s_.faults.disconnect_after);
  if (!pty_) next = std::min(next, reconnect_at_);
  return next;
}

void C550SimShell::wait(double seconds) {
  const int timeout_ms = static_cast<int>(std::clamp(std::ceil(seconds * 1000), 0.0, 5.0));
  pollfd fds[2] = {{bus_.lcm().getFileno(), POLLIN, 0}, {-1, 0, 0}};
  if (pty_) fds[1] = {pty_->master(), static_cast<short>(POLLIN | (tx_.empty() ? 0 : POLLOUT)), 0};
  if (::poll(fds, pty_ ? 2 : 1, timeout_ms) < 0 && errno != EINTR) {
    throw std::runtime_error(system_error("poll"));
  }
  if (fds[0].revents & POLLIN) bus_.handle(std::chrono::milliseconds(0));
  bus_.tick();
}

void C550SimShell::serve(double t) {
  if (!pty_) return;
  emulator_->set_ball_centre(ball_.at(now_utime()));  // where the ball is now, for a CLOSE
  receive(t);
  if (emulator_->next_output_time() <= t) {
    for (const auto& chunk : emulator_->take_output_chunks(t)) faults_.apply(chunk, tx_);
  }
  transmit();
  log_commands(t);
  for (const std::string& e : emulator_->take_events()) spdlog::info("{}", e);
}

void C550SimShell::receive(double t) {
  uint8_t buffer[512];
  for (;;) {
    const ssize_t n = ::read(pty_->master(), buffer, sizeof buffer);
    if (n > 0) {
      for (ssize_t i = 0; i < n; ++i) emulator_->feed(buffer[i], t);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EIO) {
      throw std::runtime_error(system_error(pty_->path() + ": read"));
    }
    return;
  }
}

void C550SimShell::transmit() {
  while (!tx_.empty()) {
    const size_t n = std::min<size_t>(tx_.size(), 512);
    uint8_t buffer[512];
    std::copy_n(tx_.begin(), n, buffer);
    const ssize_t written = ::write(pty_->master(), buffer, n);
    if (written > 0) {
      tx_.erase(tx_.begin(), tx_.begin() + written);
      continue;
    }
    if (written < 0 && errno == EINTR) continue;
    if (written < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EIO) {
      throw std::runtime_error(system_error(pty_->path() + ": write"));
    }
    return;  // the driver is not reading: keep the rest for POLLOUT
  }
}

void C550SimShell::log_commands(double t) {
  const std::vector<std::string> commands = emulator_->executed_commands();
  for (; logged_ < commands.size(); ++logged_) {
    spdlog::debug("command at {:.3f} s: {}", t, commands[logged_]);
    if (!log_.is_open()) continue;
    char prefix[64];
    std::snprintf(prefix, sizeof prefix, "%lld\t%.6f\t", static_cast<long long>(now_utime()), t);
    log_ << prefix << commands[logged_] << '\n';
    log_.flush();
  }
}

}  // namespace sg::sim
