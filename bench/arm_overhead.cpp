// arm_overhead: the driver's own cost per controller interaction, beyond the serial line and the
// controller's delay. Starts the real sg-c550-sim on a pseudo-terminal (the same binary users run),
// drives it with the ArmDriver core of sg-arm-driver through the real SerialPort, and prints, per
// interaction: the whole interaction, the time inside the serial stream (writing, waiting for
// echoes and replies) and the rest, the driver's overhead, with its ratio to the interaction.
//
//   build/bin/arm_overhead [--count N] [--delay-min S] [--delay-max S]
//
// A pseudo-terminal has no baud rate, so the table also gives what the same bytes would take on a
// real 38,400 8N1 line (10 bits a byte).

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <vector>

#include "arm_driver/arm_driver.hpp"
#include "arm_driver/serial_port.hpp"

extern char** environ;

namespace {

using namespace std::chrono_literals;
using stereograsp::arm_cmd_t;

/// sg-c550-sim as a child process; killed with SIGINT when this goes.
class Simulator {
 public:
  Simulator(const std::string& link, double delay_min, double delay_max) {
    const std::string bin = std::string(SG_BIN_DIR) + "/sg-c550-sim";
    std::vector<std::string> args = {bin,
                                     "--lcm-url",
                                     "udpm://239.255.76.67:7960?ttl=0",
                                     "--link",
                                     link,
                                     "--delay-min",
                                     std::to_string(delay_min),
                                     "--delay-max",
                                     std::to_string(delay_max),
                                     "--log-level",
                                     "warn"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, bin.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
      throw std::runtime_error("cannot start " + bin);
    }
    for (int i = 0; i < 200 && !std::filesystem::exists(link); ++i)
      std::this_thread::sleep_for(25ms);
    if (!std::filesystem::exists(link)) throw std::runtime_error("sg-c550-sim made no " + link);
  }
  ~Simulator() {
    kill(pid_, SIGINT);
    waitpid(pid_, nullptr, 0);
  }

 private:
  pid_t pid_ = -1;
};

arm_cmd_t move(int64_t sequence, double azimuth) {
  arm_cmd_t c{};
  c.sequence = sequence;
  c.mode = arm_cmd_t::MODE_CARTESIAN;
  c.position[0] = 0.5 * std::cos(azimuth);
  c.position[1] = 0.5 * std::sin(azimuth);
  c.position[2] = 0.30;
  c.orientation[0] = M_PI;
  c.orientation[2] = azimuth + M_PI;
  c.speed = 0.5;
  c.sender = "arm_overhead";
  return c;
}

/// The value at fraction p (0..1) of the sorted values, the nearest rank.
double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(std::lround(p * static_cast<double>(v.size() - 1)))];
}

/// What each timed interaction took: the whole, and the driver's overhead in it, seconds.
struct Timings {
  std::vector<double> interaction, overhead;
};

/// Waits (up to 30 s) until the driver reports command `sequence` executed.
void wait_executed(const sg::arm::ArmDriver& driver, int64_t sequence) {
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (driver.status().first.last_executed_sequence != sequence) {
    if (std::chrono::steady_clock::now() > deadline) {
      throw std::runtime_error("command " + std::to_string(sequence) +
                               " not executed in 30 s: " + driver.status().first.error);
    }
    std::this_thread::sleep_for(1ms);
  }
}

/// Sends count + 1 moves, alternating between two azimuths, one at a time; times all but the
/// first (which also sets SPEED).
Timings time_interactions(sg::arm::ArmDriver& driver, int count) {
  Timings t;
  for (int64_t k = 1; k <= count + 1; ++k) {
    driver.submit(move(k, 0.3 * static_cast<double>(k % 2)));
    wait_executed(driver, k);
    std::this_thread::sleep_for(50ms);  // the interaction's closing W2
    if (k == 1) continue;               // the first one also sets SPEED
    t.interaction.push_back(driver.status().first.interaction_time);
    t.overhead.push_back(driver.last_overhead());
  }
  return t;
}

/// One table row: p50, p95 and max of `v`, times `scale`, in `unit`.
void print_row(const char* name, const std::vector<double>& v, double scale, const char* unit) {
  std::printf("%-28s %10.3f %s %10.3f %s %10.3f %s\n", name, percentile(v, 0.5) * scale, unit,
              percentile(v, 0.95) * scale, unit, percentile(v, 1.0) * scale, unit);
}

/// The table: interaction, overhead and their ratio; a real line's transmission time; the goal.
void print_table(int count, double delay_min, double delay_max, const Timings& t) {
  std::printf(
      "\n%d interactions (SPEED once, then MA + W2 each) with sg-c550-sim, delay %.2f-%.2f s\n",
      count, delay_min, delay_max);
  std::printf("%-28s %12s %12s %12s\n", "", "p50", "p95", "max");
  print_row("interaction", t.interaction, 1e3, "ms");
  print_row("driver overhead", t.overhead, 1e3, "ms");
  std::vector<double> ratio(t.overhead.size());
  for (size_t i = 0; i < ratio.size(); ++i) ratio[i] = t.overhead[i] / t.interaction[i];
  print_row("overhead / interaction", ratio, 1e2, "% ");
  // MA with six angles %.4f is about 60 characters, echoed; W2's reply about 70.
  const double line_bytes = 2.0 * 60 + 5 + 2.0 * 3 + 80;
  std::printf("a real 38,400 8N1 line would add about %.0f ms of transmission per interaction\n",
              line_bytes * 10.0 / 38400.0 * 1e3);
  std::printf("goal: driver overhead < 1 ms per interaction: %s\n",
              percentile(t.overhead, 0.95) < 1e-3 ? "met (p95)" : "NOT met (p95)");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("The arm driver's own overhead per controller interaction (docs/arm.md).");
  int count = 30;
  double delay_min = 0.72, delay_max = 0.84;
  app.add_option("--count", count, "interactions to time (default 30)")
      ->check(CLI::Range(2, 10000));
  app.add_option("--delay-min", delay_min, "sg-c550-sim's shortest delay, s (default 0.72)");
  app.add_option("--delay-max", delay_max, "sg-c550-sim's longest delay, s (default 0.84)");
  CLI11_PARSE(app, argc, argv);
  try {
    const std::string link =
        (std::filesystem::temp_directory_path() / ("arm_overhead_" + std::to_string(getpid())))
            .string();
    Simulator sim(link, delay_min, delay_max);
    sg::arm::DriverSettings settings;
    sg::arm::ArmDriver driver(sg::arm::ArmGeometry::a465(), settings,
                              [&] { return sg::arm::SerialPort::open(link, {}); });
    std::jthread worker([&](std::stop_token stop) { driver.run(stop); });
    const Timings timings = time_interactions(driver, count);
    worker.request_stop();
    print_table(count, delay_min, delay_max, timings);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arm_overhead: %s\n", e.what());
    return 1;
  }
}
