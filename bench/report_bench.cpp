// The cost of sg-report's pass (issue 9): a synthetic session with every channel at its normal
// rate and no images (BLOB_LEFT/RIGHT, OBJECT_POSITION, GROUND_TRUTH 30 Hz, OBJECT_TRAJECTORY and
// GRASP_STATUS 4 Hz, ARM_STATUS 20 Hz, ARM_COMMAND 1.3 Hz, SIM_ARM_STATE 50 Hz) is written with
// lcm::LogFile, then reported through the library (statistics, CSV per channel, report.md and
// .json, plots). Each length runs in a child process of its own, so the peak RSS of each is its
// own: it must not grow from 6 to 60 minutes. Also the time to merely read the log with
// lcm::LogFile, the baseline the report's time is a ratio of.
//
//   build/bin/report_bench                 # 6 and 60 minutes
//   build/bin/report_bench --minutes 10    # one length
// Goal: a one-hour session reported in under 30 s, with memory that does not grow with the log.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <queue>
#include <string>
#include <vector>

#include "common/message_types.hpp"
#include "logger/report.hpp"

namespace {

namespace fs = std::filesystem;
constexpr int64_t kT0 = 1'700'000'000'000'000;

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // kB on Linux
}

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::array<double, 3> circle(int64_t u) {
  const double t = (u - kT0) * 1e-6;
  return {0.5 + 0.15 * std::cos(t * 0.1047), 0.15 * std::sin(t * 0.1047), 0.2};
}

/// BLOB_LEFT or BLOB_RIGHT: found (search window) while visible, else not found (full frame).
std::vector<uint8_t> blob(int64_t u, int64_t frame, bool visible, const std::array<double, 3>& x) {
  stereograsp::blob_t b{};
  b.utime = u;
  b.frame_number = frame;
  b.found = visible;
  b.mode = visible ? 1 : 2;
  b.centroid[0] = 320 + 100 * x[0];
  b.area = 400;
  return sg::encode_message(b);
}

/// OBJECT_POSITION (1 mm off the circle, NaN while occluded) or GROUND_TRUTH (always visible).
std::vector<uint8_t> position(const std::string& channel, int64_t u, bool visible,
                              const std::array<double, 3>& x) {
  stereograsp::point3_t p{};
  p.utime = u;
  p.visible = channel == "GROUND_TRUTH" || visible;
  for (int k = 0; k < 3; ++k) p.position[k] = p.visible ? x[k] + 0.001 : NAN;
  p.reprojection_error = 0.3;
  return sg::encode_message(p);
}

/// OBJECT_TRAJECTORY: 16 points of the circle 0.25 s apart, starting one period after u.
std::vector<uint8_t> trajectory(int64_t u, bool visible) {
  stereograsp::trajectory_t t{};
  t.utime = u;
  t.source_utime = u;
  t.period_us = 250'000;
  t.start_utime = u + t.period_us;
  t.num_points = 16;
  for (int k = 0; k < 16; ++k) {
    const auto p = circle(t.start_utime + k * t.period_us);
    t.position.push_back({p[0], p[1], p[2] + 0.002 * k});
    t.position_sigma.push_back({0.001, 0.001, 0.001});
  }
  t.status = visible ? 1 : 2;
  t.model = 1;
  t.model_order = 12;
  return sg::encode_message(t);
}

/// ARM_STATUS: an interaction time between 0.72 and 0.83 s.
std::vector<uint8_t> arm_status(int64_t u, const std::array<double, 3>& x) {
  stereograsp::arm_status_t a{};
  a.utime = u;
  a.interaction_time = 0.72 + 0.01 * ((u / 800'000) % 12);
  a.tool_position[0] = x[0];
  a.speed = 0.5;
  return sg::encode_message(a);
}

/// ARM_COMMAND: a Cartesian move to the ball, 40 ms after its source.
std::vector<uint8_t> arm_command(int64_t u, const std::array<double, 3>& x) {
  stereograsp::arm_cmd_t c{};
  c.utime = u;
  c.source_utime = u - 40'000;
  c.mode = 1;
  for (int k = 0; k < 3; ++k) c.position[k] = x[k];
  c.speed = 0.5;
  c.sender = "sg-grasp";
  return sg::encode_message(c);
}

/// SIM_ARM_STATE: only its time.
std::vector<uint8_t> sim_arm_state(int64_t u) {
  stereograsp::sim_arm_state_t s{};
  s.utime = u;
  return sg::encode_message(s);
}

/// GRASP_STATUS: a grasp every 30 s (q0 10 s, q1 5 s, q2 2 s, q3 1 s, q4 and success after).
std::vector<uint8_t> grasp_status(int64_t u) {
  stereograsp::grasp_status_t g{};
  g.utime = u;
  g.source_utime = u - 30'000;
  const int64_t phase = (u / 1'000'000) % 30;  // a grasp every 30 s
  g.state = phase < 10 ? 0 : phase < 15 ? 1 : phase < 17 ? 2 : phase < 18 ? 3 : 4;
  g.outcome = phase >= 18 ? 1 : 0;
  g.message = "";
  for (double& v : g.target) v = NAN;
  return sg::encode_message(g);
}

/// The message `channel` carries at time u; `frame` counts the positions written so far.
std::vector<uint8_t> message_at(const std::string& channel, int64_t u, int64_t frame) {
  const auto x = circle(u);
  const bool visible = (u / 1'000'000) % 60 < 57;  // a 3 s occlusion every minute
  if (channel == "BLOB_LEFT" || channel == "BLOB_RIGHT") return blob(u, frame, visible, x);
  if (channel == "OBJECT_POSITION" || channel == "GROUND_TRUTH")
    return position(channel, u, visible, x);
  if (channel == "OBJECT_TRAJECTORY") return trajectory(u, visible);
  if (channel == "ARM_STATUS") return arm_status(u, x);
  if (channel == "ARM_COMMAND") return arm_command(u, x);
  if (channel == "SIM_ARM_STATE") return sim_arm_state(u);
  return grasp_status(u);
}

/// Appends one event, received 3 ms after its message's time u.
void write_event(lcm::LogFile& log, const std::string& channel, int64_t u,
                 std::vector<uint8_t>& bytes) {
  lcm::LogEvent e;
  e.eventnum = 0;
  e.timestamp = u + 3000;
  e.channel = channel;
  e.datalen = static_cast<int32_t>(bytes.size());
  e.data = bytes.data();
  log.writeEvent(&e);
}

/// Writes `minutes` of session; returns the number of events.
int64_t write_session(const std::string& path, int minutes) {
  struct Stream {
    const char* channel;
    int64_t period_us;
    int64_t next;
  };
  std::vector<Stream> streams = {{"BLOB_LEFT", 33'333, 0},          {"BLOB_RIGHT", 33'333, 0},
                                 {"OBJECT_POSITION", 33'333, 0},    {"GROUND_TRUTH", 33'333, 0},
                                 {"OBJECT_TRAJECTORY", 250'000, 0}, {"ARM_STATUS", 50'000, 0},
                                 {"ARM_COMMAND", 769'231, 0},       {"SIM_ARM_STATE", 20'000, 0},
                                 {"GRASP_STATUS", 250'000, 0}};
  using Item = std::pair<int64_t, size_t>;  // next time, stream
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (size_t i = 0; i < streams.size(); ++i) queue.push({kT0 + static_cast<int64_t>(i), i});
  const int64_t end = kT0 + static_cast<int64_t>(minutes) * 60'000'000;
  lcm::LogFile log(path, "w");
  int64_t events = 0, frame = 0;
  while (!queue.empty()) {
    const auto [u, i] = queue.top();
    queue.pop();
    if (u >= end) continue;
    queue.push({u + streams[i].period_us, i});
    const std::string channel = streams[i].channel;
    std::vector<uint8_t> bytes = message_at(channel, u, frame);
    if (channel == "OBJECT_POSITION") ++frame;
    write_event(log, channel, u, bytes);
    ++events;
  }
  return events;
}

/// Runs in a child: writes, reads (baseline), reports; prints one line.
int measure(int minutes) {
  const std::string dir =
      fs::temp_directory_path() / ("sg_report_bench_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string path = dir + "/session.lcmlog";
  const int64_t events = write_session(path, minutes);
  const double size_mb = fs::file_size(path) / 1e6;
  const double rss_before = peak_rss_mb();

  double t = now_s();
  {
    lcm::LogFile log(path, "r");
    int64_t n = 0;
    while (log.readNextEvent()) ++n;
    if (n != events)
      std::fprintf(stderr, "read %lld of %lld events\n", (long long)n, (long long)events);
  }
  const double baseline = now_s() - t;

  sg::logger::ReportOptions options;
  options.out_dir = dir + "/report";
  t = now_s();
  const sg::logger::ReportResult r = sg::logger::make_report(path, options);
  const double report = now_s() - t;

  options.csv = false;
  options.plots = false;
  options.out_dir = dir + "/report_stats_only";
  t = now_s();
  sg::logger::make_report(path, options);
  const double stats_only = now_s() - t;

  std::printf(
      "%3d min | %8lld events | %7.1f MB | read %6.2f s | report %6.2f s (%5.1fx read) "
      "| stats only %6.2f s | peak RSS %6.1f MB (%.1f MB before the report) | h=4 RMS "
      "%.4f m\n",
      minutes, static_cast<long long>(events), size_mb, baseline, report, report / baseline,
      stats_only, peak_rss_mb(), rss_before,
      r.summary.prediction.size() > 1 ? r.summary.prediction[1].vs_truth.rms : NAN);
  std::fflush(stdout);
  fs::remove_all(dir);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> lengths = {6, 60};
  if (argc == 3 && std::strcmp(argv[1], "--minutes") == 0) lengths = {std::atoi(argv[2])};
  std::printf("sg-report pass over synthetic sessions (no images), CSV and plots included\n");
  std::fflush(stdout);
  for (int minutes : lengths) {
    const pid_t pid = fork();
    if (pid == 0) _exit(measure(minutes));
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return 1;
  }
  std::printf("goal: 60 min under 30 s, peak RSS the same for 6 and 60 min\n");
  return 0;
}
