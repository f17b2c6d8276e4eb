// sg-c550-sim: a CRS C550 controller and its arm on a pseudo-terminal (docs/arm.md). sg-arm-driver
// opens the printed /dev/pts/N (or the --link path) as it would a real serial port. Publishes the
// arm's true state on SIM_ARM_STATE for sg-camera-sim, and grasps the ball GROUND_TRUTH says is
// there. Fault injection (garbled bytes, lost ACKs, a line that drops and comes back) tests the
// driver's recovery.
//
//   sg-c550-sim --link /tmp/c550                   # then: sg-arm-driver --device /tmp/c550
//   sg-c550-sim --garble-rate 0.001 --drop-ack-rate 0.01 --log-commands commands.tsv
//   sg-c550-sim --disconnect-after 5 --reconnect-after 2
//   sg-c550-sim --link /tmp/c550 --holding         # the ball in the gripper (robot calibration)

#include <fcntl.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>

#include "arm_driver/kinematics.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "sim/c550_controller.hpp"
#include "sim/c550_emulator.hpp"
#include "stereograsp/point3_t.hpp"
#include "stereograsp/sim_arm_state_t.hpp"

namespace {

using sg::sim::C550Controller;
using sg::sim::C550Emulator;

struct Options {
  int slave = 1;
  double delay_min = 0.72;
  double delay_max = 0.84;
  int speed = 50;
  int64_t seed = 1;
  std::string link;
  double garble_rate = 0;
  double drop_ack_rate = 0;
  double disconnect_after = 0;  // 0: never
  double reconnect_after = 1.0;
  std::string log_commands;
  double state_rate = 50;
  bool holding = false;
};

std::string system_error(const std::string& what) { return what + ": " + std::strerror(errno); }

/// A pseudo-terminal whose slave side is raw at 38,400 baud. The simulator keeps a slave fd
/// open itself so the master never reads EIO while no driver has the device open.
class PseudoTerminal {
 public:
  PseudoTerminal() {
    master_ = posix_openpt(O_RDWR | O_NOCTTY);
    if (master_ < 0) throw std::runtime_error(system_error("posix_openpt"));
    if (grantpt(master_) != 0 || unlockpt(master_) != 0) {
      close_all();
      throw std::runtime_error(system_error("grantpt/unlockpt on the pseudo-terminal"));
    }
    const char* name = ptsname(master_);
    if (!name) {
      close_all();
      throw std::runtime_error(system_error("ptsname"));
    }
    path_ = name;
    slave_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY);
    if (slave_ < 0) {
      close_all();
      throw std::runtime_error(system_error(path_ + ": open"));
    }
    make_raw();
    if (fcntl(master_, F_SETFL, fcntl(master_, F_GETFL) | O_NONBLOCK) != 0) {
      close_all();
      throw std::runtime_error(system_error("fcntl O_NONBLOCK on the pseudo-terminal"));
    }
  }
  ~PseudoTerminal() { close_all(); }
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  int master() const { return master_; }
  const std::string& path() const { return path_; }

 private:
  void make_raw() {
    termios tio{};
    if (tcgetattr(slave_, &tio) != 0) throw std::runtime_error(system_error(path_ + ": tcgetattr"));
    cfmakeraw(&tio);
    cfsetispeed(&tio, B38400);
    cfsetospeed(&tio, B38400);
    if (tcsetattr(slave_, TCSANOW, &tio) != 0) {
      throw std::runtime_error(system_error(path_ + ": tcsetattr"));
    }
  }
  void close_all() {
    if (slave_ >= 0) ::close(slave_);
    if (master_ >= 0) ::close(master_);
    slave_ = master_ = -1;
  }

  int master_ = -1;
  int slave_ = -1;
  std::string path_;
};

/// PATH -> target, replaced atomically; removed by remove() if it still points there.
class Symlink {
 public:
  explicit Symlink(std::string path) : path_(std::move(path)) {}
  ~Symlink() { remove(); }
  void point_to(const std::string& target) {
    if (path_.empty()) return;
    const std::string temporary = path_ + ".tmp" + std::to_string(getpid());
    ::unlink(temporary.c_str());
    if (::symlink(target.c_str(), temporary.c_str()) != 0 ||
        ::rename(temporary.c_str(), path_.c_str()) != 0) {
      throw std::runtime_error(system_error("--link " + path_ + " -> " + target));
    }
    target_ = target;
  }
  void remove() {
    if (path_.empty() || target_.empty()) return;
    std::error_code error;
    if (std::filesystem::read_symlink(path_, error) == target_) ::unlink(path_.c_str());
    target_.clear();
  }

 private:
  std::string path_;
  std::string target_;
};

/// Replaces bytes and drops ACKs at the configured rates, from its own seeded generator.
class FaultInjector {
 public:
  FaultInjector(double garble_rate, double drop_ack_rate, uint32_t seed)
      : garble_rate_(garble_rate), drop_ack_rate_(drop_ack_rate), rng_(seed) {}

  void apply(const C550Emulator::Chunk& chunk, std::deque<uint8_t>& out) {
    if (chunk.ack && chance(drop_ack_rate_)) {
      ++dropped_;
      spdlog::debug("fault: ACK dropped");
      return;
    }
    for (uint8_t byte : chunk.bytes) {
      if (chance(garble_rate_)) {
        const uint8_t garbled = static_cast<uint8_t>(byte + 1 + rng_() % 255);
        spdlog::debug("fault: byte 0x{:02X} garbled to 0x{:02X}", byte, garbled);
        byte = garbled;
        ++garbled_;
      }
      out.push_back(byte);
    }
  }
  int64_t garbled() const { return garbled_; }
  int64_t dropped() const { return dropped_; }

 private:
  bool chance(double p) { return p > 0 && static_cast<double>(rng_()) / 4294967296.0 < p; }

  double garble_rate_, drop_ack_rate_;
  std::mt19937 rng_;
  int64_t garbled_ = 0, dropped_ = 0;
};

stereograsp::sim_arm_state_t arm_state(const C550Controller& c550, double t) {
  stereograsp::sim_arm_state_t m{};
  m.utime = sg::now_utime();
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

/// The simulator's running state: the line (which comes and goes), the controller (which stays).
class Simulator {
 public:
  Simulator(const Options& o, C550Controller& controller, sg::Bus& bus)
      : o_(o),
        controller_(controller),
        bus_(bus),
        link_(o.link),
        faults_(o.garble_rate, o.drop_ack_rate, static_cast<uint32_t>(o.seed) ^ 0x5eedu) {
    if (!o.log_commands.empty()) {
      log_.open(o.log_commands, std::ios::app);
      if (!log_) throw std::runtime_error("--log-commands " + o.log_commands + ": cannot append");
    }
    bus_.subscribe<stereograsp::point3_t>(
        "GROUND_TRUTH", [this](const stereograsp::point3_t& p, const sg::ReceiveInfo&) {
          const Eigen::Vector3d centre(p.position[0], p.position[1], p.position[2]);
          ball_ = centre.allFinite() ? std::optional(centre) : std::nullopt;
          if (emulator_) emulator_->set_ball_centre(ball_);
        });
  }

  int run() {
    connect();
    double next_state = 0;
    while (!sg::shutdown_requested()) {
      const double t = now();
      schedule_line(t);
      if (t >= next_state) {
        bus_.publish("SIM_ARM_STATE", arm_state(controller_, t));
        next_state += 1.0 / o_.state_rate;
        if (next_state < t) next_state = t + 1.0 / o_.state_rate;  // fell behind: skip ahead
      }
      wait(std::min(next_state, next_event()) - now());
      serve(now());
    }
    spdlog::info("stopping: {} bytes garbled, {} ACKs dropped", faults_.garbled(),
                 faults_.dropped());
    return 0;
  }

 private:
  double now() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

  void connect() {
    pty_ = std::make_unique<PseudoTerminal>();
    emulator_ = std::make_unique<C550Emulator>(controller_, o_.slave);
    emulator_->set_ball_centre(ball_);
    logged_ = 0;
    tx_.clear();
    link_.point_to(pty_->path());
    std::printf("sg-c550-sim: serial device %s\n", pty_->path().c_str());
    std::fflush(stdout);
  }

  /// Drops the line once at --disconnect-after and brings a new one --reconnect-after later.
  void schedule_line(double t) {
    if (pty_ && !disconnected_ && o_.disconnect_after > 0 && t >= o_.disconnect_after) {
      spdlog::info("disconnecting {} (--disconnect-after {} s)", pty_->path(), o_.disconnect_after);
      disconnected_ = true;
      link_.remove();
      emulator_.reset();
      pty_.reset();
      reconnect_at_ = t + o_.reconnect_after;
    } else if (!pty_ && t >= reconnect_at_) {
      connect();
    }
  }

  double next_event() const {
    double next = std::numeric_limits<double>::infinity();
    if (emulator_) next = emulator_->next_output_time();
    if (pty_ && !disconnected_ && o_.disconnect_after > 0)
      next = std::min(next, o_.disconnect_after);
    if (!pty_) next = std::min(next, reconnect_at_);
    return next;
  }

  void wait(double seconds) {
    const int timeout_ms = static_cast<int>(std::clamp(std::ceil(seconds * 1000), 0.0, 5.0));
    pollfd fds[2] = {{bus_.lcm().getFileno(), POLLIN, 0}, {-1, 0, 0}};
    if (pty_)
      fds[1] = {pty_->master(), static_cast<short>(POLLIN | (tx_.empty() ? 0 : POLLOUT)), 0};
    if (::poll(fds, pty_ ? 2 : 1, timeout_ms) < 0 && errno != EINTR) {
      throw std::runtime_error(system_error("poll"));
    }
    if (fds[0].revents & POLLIN) bus_.handle(std::chrono::milliseconds(0));
  }

  void serve(double t) {
    if (!pty_) return;
    receive(t);
    if (emulator_->next_output_time() <= t) {
      for (const auto& chunk : emulator_->take_output_chunks(t)) faults_.apply(chunk, tx_);
    }
    transmit();
    log_commands(t);
    for (const std::string& e : emulator_->take_events()) spdlog::info("{}", e);
  }

  void receive(double t) {
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

  void transmit() {
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

  void log_commands(double t) {
    const std::vector<std::string> commands = emulator_->executed_commands();
    for (; logged_ < commands.size(); ++logged_) {
      spdlog::debug("command at {:.3f} s: {}", t, commands[logged_]);
      if (!log_.is_open()) continue;
      char prefix[64];
      std::snprintf(prefix, sizeof prefix, "%lld\t%.6f\t", static_cast<long long>(sg::now_utime()),
                    t);
      log_ << prefix << commands[logged_] << '\n';
      log_.flush();
    }
  }

  const Options& o_;
  C550Controller& controller_;
  sg::Bus& bus_;
  Symlink link_;
  FaultInjector faults_;
  std::ofstream log_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::unique_ptr<PseudoTerminal> pty_;
  std::unique_ptr<C550Emulator> emulator_;
  std::deque<uint8_t> tx_;
  std::optional<Eigen::Vector3d> ball_;
  size_t logged_ = 0;
  bool disconnected_ = false;
  double reconnect_at_ = 0;
};

/// A flag's value when given, else the config's `c550_sim.<key>`, else the built-in default.
template <class T>
void settle(const CLI::App& app, const char* flag, const sg::Config& config, const char* key,
            T& value) {
  if (app.count(flag) == 0) value = config.get<T>(std::string("c550_sim.") + key, value);
}

void check(bool ok, const std::string& what) {
  if (!ok) throw std::runtime_error(what);
}

void load_options(const CLI::App& app, const sg::Config& c, Options& o) {
  settle(app, "--slave", c, "slave", o.slave);
  settle(app, "--delay-min", c, "delay_min", o.delay_min);
  settle(app, "--delay-max", c, "delay_max", o.delay_max);
  settle(app, "--speed", c, "speed", o.speed);
  settle(app, "--seed", c, "seed", o.seed);
  settle(app, "--link", c, "link", o.link);
  settle(app, "--garble-rate", c, "garble_rate", o.garble_rate);
  settle(app, "--drop-ack-rate", c, "drop_ack_rate", o.drop_ack_rate);
  settle(app, "--disconnect-after", c, "disconnect_after", o.disconnect_after);
  settle(app, "--reconnect-after", c, "reconnect_after", o.reconnect_after);
  settle(app, "--log-commands", c, "log_commands", o.log_commands);
  settle(app, "--state-rate", c, "state_rate", o.state_rate);
  settle(app, "--holding", c, "holding", o.holding);
  check(o.slave >= 1 && o.slave <= 127, "--slave / c550_sim.slave must be 1..127");
  check(o.delay_min >= 0 && o.delay_min <= o.delay_max,
        "--delay-min / --delay-max: need 0 <= delay-min <= delay-max");
  check(o.speed >= 1 && o.speed <= 100, "--speed / c550_sim.speed must be 1..100");
  check(o.seed >= 0 && o.seed <= 0xFFFFFFFFll, "--seed / c550_sim.seed must be 0..4294967295");
  check(o.garble_rate >= 0 && o.garble_rate <= 1, "--garble-rate must be a probability 0..1");
  check(o.drop_ack_rate >= 0 && o.drop_ack_rate <= 1, "--drop-ack-rate must be a probability 0..1");
  check(o.disconnect_after >= 0, "--disconnect-after must be >= 0 seconds (0: never)");
  check(o.reconnect_after >= 0, "--reconnect-after must be >= 0 seconds");
  check(o.state_rate > 0 && std::isfinite(o.state_rate), "--state-rate must be positive");
}

sg::sim::C550Params controller_params(const Options& o, const sg::Config& c) {
  sg::sim::C550Params p;
  p.delay_min = o.delay_min;
  p.delay_max = o.delay_max;
  p.seed = static_cast<uint32_t>(o.seed);
  p.speed_percent = o.speed;
  p.gripper_time = c.get<double>("c550_sim.gripper_time", p.gripper_time);
  p.gripper_open_width = c.get<double>("c550_sim.gripper_open_width", p.gripper_open_width);
  p.gripper_closed_width = c.get<double>("c550_sim.gripper_closed_width", p.gripper_closed_width);
  p.grasp_tolerance = c.get<double>("c550_sim.grasp_tolerance", p.grasp_tolerance);
  p.ball_radius = c.get<double>("c550_sim.ball_radius", p.ball_radius);
  p.start_holding = o.holding;
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "A simulated CRS C550 controller and arm on a pseudo-terminal: the ACI link layer and "
      "RAPL-II commands of docs/arm.md, for sg-arm-driver. Prints 'sg-c550-sim: serial device "
      "/dev/pts/N'; publishes SIM_ARM_STATE; grasps the GROUND_TRUTH ball. Every flag can also "
      "be set under 'c550_sim:' in --config (same name, with _ for -); flags win.",
      "sg-c550-sim"};
  sg::CommonOptions common;
  sg::add_common_options(app, common);
  Options o;
  app.add_option("--slave", o.slave, "ACI slave number 1..127 (default 1)");
  app.add_option("--delay-min", o.delay_min,
                 "shortest delay from a motion command to its ACK, s (default 0.72)");
  app.add_option("--delay-max", o.delay_max, "longest such delay, s (default 0.84)");
  app.add_option("--speed", o.speed, "SPEED at power-up, percent (default 50)");
  app.add_option("--seed", o.seed, "seed of the delay draws and the fault injection (default 1)");
  app.add_option("--link", o.link,
                 "make PATH a symlink to the pseudo-terminal (re-pointed on reconnect, removed "
                 "at exit)");
  app.add_option("--garble-rate", o.garble_rate,
                 "probability that a byte the controller sends is replaced by a random one");
  app.add_option("--drop-ack-rate", o.drop_ack_rate,
                 "probability that an ACK the controller sends is lost");
  app.add_option("--disconnect-after", o.disconnect_after,
                 "close the pseudo-terminal after S seconds, then open a new one (arm state "
                 "kept, line back in ACI mode); 0: never (default)");
  app.add_option("--reconnect-after", o.reconnect_after,
                 "seconds without a line after --disconnect-after (default 1.0)");
  app.add_option("--log-commands", o.log_commands,
                 "append each RAPL command line received to FILE: utime, seconds since start, "
                 "command, tab-separated");
  app.add_option("--state-rate", o.state_rate, "SIM_ARM_STATE messages per second (default 50)");
  app.add_flag("--holding", o.holding,
               "start with the gripper closed on the ball (SIM_ARM_STATE holding_object, so "
               "sg-camera-sim draws the ball at the tool centre point) until the first OPEN: "
               "for sg-calibrate robot");

  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    load_options(app, config, o);
    sg::install_shutdown_handlers();
    C550Controller controller(sg::arm::load_arm_geometry(config), controller_params(o, config));
    sg::Bus bus(common.lcm_url);
    Simulator simulator(o, controller, bus);
    return simulator.run();
  });
}
