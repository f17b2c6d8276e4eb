// How often the whole system grasps the moving ball (issues 8, 14): many grasp trials in simulated
// time, in one process, composed of the product's own parts (system/grasp_trial.hpp: rendered
// frames, sg-vision's stereo step, the Burg predictor at 4 Hz and its OBJECT_TRAJECTORY, sg-grasp's
// node, sg-arm-driver's core speaking RAPL-II bytes to the C550 emulator on a simulated line). Per
// trial, drawn from --seed: the ball's phase, circle radius 0.10-0.15 m, speed 0.5-2 rpm, Y drift
// 0-0.01 m/s (the paper's back-and-forth, reversing every 20 s), the grasp command at a time after
// the warm-up, and a total occlusion from 1 s before the grasp command, 3-4 s long, so it covers
// the close. Each trial runs with prediction and with --no-prediction (aim at the last
// measurement); prints the success rates (the controller's truth: it holds the ball after the
// lift), how often the machine's own judgement agreed, and the miss distances (TCP to the true ball
// centre when the CLOSE executes).
//
//   build/bin/grasp_success                        # 100 trials x 2 modes, rendered, 2 threads
//   build/bin/grasp_success --no-render --trials 500 --verbose
//   build/bin/grasp_success --occluded-fraction 0  # no occlusion
//   build/bin/grasp_success --kalman               # the Kalman predictor's mode too
//   build/bin/grasp_success --no-replan            # approaches once sent stand (the rule's effect)
//   build/bin/grasp_success --no-render --kalman --sweep speed --out docs/img
// A sweep (issue 17: "the curves no paper shows") runs --trials trials at each of its points in
// every mode, each point with the same draws (the same seeds) but for the swept quantity, and
// writes DIR/grasp_sweep_NAME.{md,dat,gp,png}: the table with 95% Wilson intervals and the plot.
//   interaction: the C550's interaction time, s (delays drawn in +-0.06 s around it)
//   speed:       the ball's speed on its circle, rpm
//   occlusion:   the total occlusion's length, s, from 1 s before the grasp command (0: none)
// Goal: at least 98% of 100 rendered trials with prediction.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <numbers>
#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "logger/plot.hpp"
#include "system/calibration_trial.hpp"
#include "system/grasp_trial.hpp"

namespace {

struct Options {
  int trials = 100;
  uint64_t seed = 1;
  int threads = 2;
  bool no_render = false;
  bool only_baseline = false;  // --no-prediction: the baseline alone
  bool skip_baseline = false;
  bool kalman = false;         // --kalman: the Kalman predictor's mode too
  bool no_replan = false;      // --no-replan: an approach once sent stands (before issue 17's rule)
  std::string sweep;           // interaction, speed or occlusion: success against it
  std::vector<double> points;  // the sweep's values (empty: its defaults)
  std::string out = ".";       // where a sweep's table, data and plot go
  bool verbose = false;
  int only = -1;  // --trial: only this trial of the draw (the others are not run)
  double occluded_fraction = 1.0;
  double warmup = 40.0;
  double grasp_window = 20.0;
  double frame_rate = 4.0;
  double pixel_sigma = 0.25;          // px per axis, --no-render (the camera model)
  std::string selection = "scored";   // vision's rule: scored or the paper's largest region
  std::string calibration = "robot";  // robot: calibrated by the arm first; true: the simulator's
  std::optional<sg::vision::StereoCalibration> cameras;  // the robot-guided calibration's result
};

/// How the arm is aimed: the Burg predictor's forecast (the product), the last measurement (the
/// --no-prediction baseline), or a constant-velocity Kalman filter's forecast behind the same
/// interface (its sigmas estimated the same way, so it too waits until sure).
enum class Mode { kPrediction, kNoPrediction, kKalman };

const char* name_of(Mode m) {
  switch (m) {
    case Mode::kPrediction:
      return "prediction (Burg)";
    case Mode::kNoPrediction:
      return "no prediction";
    case Mode::kKalman:
      return "Kalman baseline";
  }
  return "?";
}

void apply_mode(Mode m, sg::system::TrialParams& p) {
  p.grasp.use_prediction = m != Mode::kNoPrediction;
  if (m == Mode::kKalman) p.predictor.model = sg::predictor::Model::kKalman;
}

/// Sets the swept quantity of a trial's draw (Sweep::apply).
using Tweak = std::function<void(sg::system::TrialParams&)>;

/// Trial `index`'s draw: the same for every mode.
sg::system::TrialParams draw_trial(const Options& o, int index) {
  std::mt19937_64 rng(o.seed * 1'000'003ULL + static_cast<uint64_t>(index));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sg::system::TrialParams p = sg::system::paper_trial(rng());
  auto& s = p.sim.scenario;
  s.phase = 2 * std::numbers::pi * u(rng);
  s.radius = 0.10 + 0.05 * u(rng);
  s.rpm = 0.5 + 1.5 * u(rng);
  s.drift_speed = 0.01 * u(rng);
  p.grasp_time = o.warmup + o.grasp_window * u(rng);
  const bool occluded = u(rng) < o.occluded_fraction;
  const double duration = 3.0 + u(rng);
  if (occluded) p.sim.occlusion.episodes = {{p.grasp_time - 1.0, duration}};
  p.render = !o.no_render;
  p.frame_rate = o.frame_rate;
  p.pixel_sigma = o.pixel_sigma;
  p.tracker.selection =
      o.selection == "largest" ? sg::vision::Selection::kLargest : sg::vision::Selection::kScored;
  p.calibration = o.cameras;
  if (o.no_replan) p.grasp.max_replans = 0;
  return p;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double k = q * static_cast<double>(v.size() - 1);
  const size_t i = static_cast<size_t>(k);
  if (i + 1 >= v.size()) return v.back();
  return v[i] + (k - static_cast<double>(i)) * (v[i + 1] - v[i]);
}

struct ModeSummary {
  const char* name;
  std::vector<sg::system::TrialResult> results;
  double seconds = 0;
};

/// The draw's index of the i-th trial run: i, or --trial's.
int index_of(const Options& o, int i) { return o.only >= 0 ? o.only : i; }

/// --verbose: a line per trial.
void print_trials(const Options& o, const ModeSummary& m, const Tweak& tweak) {
  std::printf("\n%s, per trial:\n", m.name);
  std::printf(
      "trial  rpm  r(m) drift  grasp_s  close_s held mach  miss_mm  aim_mm  dT_ms  age_s  "
      "vis_mm re  state / message\n");
  for (int i = 0; i < static_cast<int>(m.results.size()); ++i) {
    auto p = draw_trial(o, index_of(o, i));
    if (tweak) tweak(p);
    const auto& r = m.results[static_cast<size_t>(i)];
    std::printf(
        "%5d %4.2f %5.3f %5.4f %7.2f %8.2f %4s %4s %8.1f %7.1f %6.0f %6.2f %7.2f %2d  %s / %s%s\n",
        index_of(o, i), p.sim.scenario.rpm, p.sim.scenario.radius, p.sim.scenario.drift_speed,
        r.grasp_time, r.close_time, r.success ? "yes" : "no", sg::grasp::to_string(r.outcome),
        r.miss_distance * 1e3, r.aim_error * 1e3, r.timing_error * 1e3, r.track_age,
        r.vision_rms * 1e3, r.replans, sg::grasp::to_string(r.final_state), r.message.c_str(),
        r.arm_rejection.empty() ? "" : (" [arm: " + r.arm_rejection + "]").c_str());
    if (o.only >= 0) std::printf("      approach sent: %s\n", r.approach_message.c_str());
  }
}

ModeSummary run_mode(const Options& o, Mode mode, const Tweak& tweak = {}) {
  ModeSummary m{name_of(mode), {}, 0};
  const int n = o.only >= 0 ? 1 : o.trials;
  m.results.resize(static_cast<size_t>(n));
  std::atomic<int> next{0};
  const auto start = std::chrono::steady_clock::now();
  auto worker = [&] {
    for (int i = next++; i < n; i = next++) {
      sg::system::TrialParams p = draw_trial(o, index_of(o, i));
      if (tweak) tweak(p);
      apply_mode(mode, p);
      m.results[static_cast<size_t>(i)] = sg::system::run_grasp_trial(p);
    }
  };
  std::vector<std::thread> pool;
  for (int k = 0; k < std::max(1, o.threads); ++k) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (o.verbose) print_trials(o, m, tweak);
  return m;
}

/// The 95% Wilson score interval of k successes in n.
std::pair<double, double> wilson(int k, int n) {
  if (n == 0) return {0, 1};
  const double z = 1.959964, nn = n, ph = k / nn;
  const double c = (ph + z * z / (2 * nn)) / (1 + z * z / nn);
  const double h = z * std::sqrt(ph * (1 - ph) / nn + z * z / (4 * nn * nn)) / (1 + z * z / nn);
  return {std::max(0.0, c - h), std::min(1.0, c + h)};
}

int held_of(const ModeSummary& m) {
  int held = 0;
  for (const auto& r : m.results) held += r.success;
  return held;
}

void print_table(const Options& o, const std::vector<ModeSummary>& modes) {
  std::printf(
      "\ngrasp_success: %d trials, seed %llu, %s, %s, %d thread(s), occluded fraction %.2f\n",
      static_cast<int>(modes.front().results.size()), static_cast<unsigned long long>(o.seed),
      o.no_render ? "camera model (--no-render)" : "rendered frames + vision",
      o.cameras ? "robot-guided calibration" : "the simulator's true cameras", o.threads,
      o.occluded_fraction);
  std::printf(
      "\n| mode | success (held after lift) | 95%% interval | machine agrees | closed | refused | "
      "arm refusals | re-plans (trials) | CLOSEs given way | miss p50 | miss p95 | miss max | "
      "run time |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const ModeSummary& m : modes) {
    int held = 0, agree = 0, closed = 0, refused = 0, rejected = 0, replans = 0, replanned = 0;
    int given_way = 0;
    std::vector<double> miss;
    for (const auto& r : m.results) {
      held += r.success, agree += r.machine_agrees, closed += r.closed, refused += r.refused;
      rejected += r.rejected, replans += r.replans, replanned += r.replans > 0;
      given_way += r.gripper_actions_dropped;
      if (r.closed) miss.push_back(r.miss_distance * 1e3);
    }
    const int n = static_cast<int>(m.results.size());
    const auto [lo, hi] = wilson(held, n);
    std::printf(
        "| %s | %d/%d (%.0f%%) | %.1f-%.1f%% | %d/%d | %d | %d | %d | %d (%d) | %d | %.1f mm | "
        "%.1f mm | %.1f mm | %.0f s |\n",
        m.name, held, n, 100.0 * held / n, 100 * lo, 100 * hi, agree, n, closed, refused, rejected,
        replans, replanned, given_way, percentile(miss, 0.5), percentile(miss, 0.95),
        percentile(miss, 1.0), m.seconds);
  }
  std::vector<double> vision;
  double pooled_sq = 0, pooled_n = 0;
  for (const auto& r : modes.front().results) {
    if (!std::isfinite(r.vision_rms)) continue;
    vision.push_back(r.vision_rms * 1e3);
    pooled_sq += r.vision_rms * r.vision_rms * static_cast<double>(r.vision_samples);
    pooled_n += static_cast<double>(r.vision_samples);
  }
  if (!o.no_render && !vision.empty())
    std::printf(
        "\nvision 3D error (ball not carried): RMS over all %.0f sightings %.2f mm; each trial's "
        "RMS median %.2f mm, p95 %.2f mm, max %.2f mm\n",
        pooled_n, 1e3 * std::sqrt(pooled_sq / std::max(1.0, pooled_n)), percentile(vision, 0.5),
        percentile(vision, 0.95), percentile(vision, 1.0));
  std::printf("grasp tolerance of the C550 model: %.0f mm\n",
              sg::sim::C550Params{}.grasp_tolerance * 1e3);
}

/// One of the three sweeps: its values and how a value sets a trial.
struct Sweep {
  std::string name;
  std::string axis;  // the plot's x label
  std::vector<double> defaults;
  std::function<void(sg::system::TrialParams&, double)> apply;
};

Sweep sweep_named(const std::string& name) {
  if (name == "interaction")
    return {name,
            "C550 interaction time (s)",
            {0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0},
            [](sg::system::TrialParams& p, double x) {
              p.c550.delay_min = std::max(0.0, x - 0.06);  // the paper's 0.72-0.84 s: +-0.06 s
              p.c550.delay_max = x + 0.06;
            }};
  if (name == "speed")
    return {name,
            "ball speed (rpm)",
            {0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0},
            [](sg::system::TrialParams& p, double x) { p.sim.scenario.rpm = x; }};
  return {"occlusion",
          "occlusion length (s)",
          {0, 1, 2, 3, 4, 5},
          [](sg::system::TrialParams& p, double x) {
            p.sim.occlusion.episodes.clear();
            if (x > 0) p.sim.occlusion.episodes = {{p.grasp_time - 1.0, x}};
          }};
}

/// The sweep's plot: held rate with its 95% interval against the swept value, a line per mode.
std::string sweep_script(const Sweep& sw, const Options& o, const std::vector<Mode>& modes,
                         const std::vector<int>& blocks) {
  using sg::logger::gnuplot_string;
  namespace pal = sg::logger::palette;
  const sg::logger::Rgb colours[] = {pal::kBlue, pal::kOrange, pal::kGreen};
  const std::string base = "grasp_sweep_" + sw.name;
  char title[256];
  std::snprintf(title, sizeof title, "grasp success, %d trials a point, seed %llu, %s", o.trials,
                static_cast<unsigned long long>(o.seed),
                o.no_render ? "camera model" : "rendered frames + vision");
  std::string g = "set terminal pngcairo size 800,500 font ',11'\nset output '" + base +
                  ".png'\nset title " + gnuplot_string(title) + "\nset xlabel " +
                  gnuplot_string(sw.axis) +
                  "\nset ylabel 'held after the lift (%)'\nset yrange [0:105]\n"
                  "set grid lc rgb '" +
                  pal::kGrid.hex() + "'\nset key below\nplot ";
  bool first = true;
  for (size_t i = 0; i < modes.size(); ++i) {
    if (blocks[i] < 0) continue;
    const std::string c = colours[i % 3].hex(), idx = std::to_string(blocks[i]);
    g += std::string(first ? "" : ", ") + "'" + base + ".dat' index " + idx +
         " using 1:2:3:4 with yerrorbars lc rgb '" + c + "' pt 7 notitle, '" + base +
         ".dat' index " + idx + " using 1:2 with lines lw 2 lc rgb '" + c + "' title " +
         gnuplot_string(name_of(modes[i]));
    first = false;
  }
  return g + "\n";
}

/// DIR/grasp_sweep_NAME.md (the table), .dat, .gp and, when gnuplot is installed, .png.
void write_sweep(const Options& o, const Sweep& sw, const std::vector<Mode>& modes,
                 const std::vector<std::vector<std::vector<double>>>& rows,
                 const std::string& table) {
  namespace lg = sg::logger;
  std::filesystem::create_directories(o.out);
  const std::string base = "grasp_sweep_" + sw.name;
  lg::GnuplotData data;
  std::vector<int> blocks;
  for (size_t i = 0; i < modes.size(); ++i)
    blocks.push_back(data.add_block(
        std::string(name_of(modes[i])) + ": value, held %, 95% interval low %, high %", rows[i]));
  data.save(o.out + "/" + base + ".dat");
  lg::write_text_file(o.out + "/" + base + ".gp", sweep_script(sw, o, modes, blocks));
  lg::write_text_file(o.out + "/" + base + ".md", table);
  try {
    lg::run_gnuplot(lg::find_gnuplot(), o.out, base + ".gp");
    std::printf("\nwrote %s/%s.{md,dat,gp,png}\n", o.out.c_str(), base.c_str());
  } catch (const lg::GnuplotMissing& e) {
    std::printf("\nwrote %s/%s.{md,dat,gp}; no plot: %s\n", o.out.c_str(), base.c_str(), e.what());
  }
}

/// Runs a sweep in every mode; prints and writes its table, data and plot.
void run_sweep(const Options& o, const std::vector<Mode>& modes) {
  const Sweep sw = sweep_named(o.sweep);
  const std::vector<double> xs = o.points.empty() ? sw.defaults : o.points;
  std::vector<std::vector<std::vector<double>>> rows(modes.size());
  std::string table = "| " + sw.axis;
  for (Mode m : modes) table += std::string(" | ") + name_of(m);
  table += " |\n|---";
  for (size_t i = 0; i < modes.size(); ++i) table += "|---";
  table += "|\n";
  for (double x : xs) {
    char cell[96];
    std::snprintf(cell, sizeof cell, "| %g", x);
    table += cell;
    for (size_t i = 0; i < modes.size(); ++i) {
      const ModeSummary m =
          run_mode(o, modes[i], [&](sg::system::TrialParams& p) { sw.apply(p, x); });
      const int held = held_of(m), n = static_cast<int>(m.results.size());
      const auto [lo, hi] = wilson(held, n);
      rows[i].push_back({x, 100.0 * held / n, 100 * lo, 100 * hi});
      std::snprintf(cell, sizeof cell, " | %d/%d (%.0f-%.0f%%)", held, n, 100 * lo, 100 * hi);
      table += cell;
      std::fprintf(stderr, "sweep %s = %g, %s: %d/%d held (%.0f s)\n", sw.name.c_str(), x, m.name,
                   held, n, m.seconds);
    }
    table += " |\n";
  }
  char head[256];
  std::snprintf(head, sizeof head,
                "grasp_success --sweep %s: %d trials a point, seed %llu (the same draws at every "
                "point), %s\n\n",
                sw.name.c_str(), o.trials, static_cast<unsigned long long>(o.seed),
                o.no_render ? "camera model (--no-render: projected truth + pixel noise)"
                            : "rendered frames + vision");
  std::printf("\n%s%s", head, table.c_str());
  write_sweep(o, sw, modes, rows, std::string(head) + table);
}
/// The lab's calibration, once for every trial: robot-guided, in simulated time, on the first
/// trial's scene (the rig is the same in all).
sg::vision::StereoCalibration calibrate(const Options& o) {
  const auto start = std::chrono::steady_clock::now();
  const sg::system::CalibrationTrialResult r =
      sg::system::run_calibration_trial(sg::system::calibration_trial_for(draw_trial(o, 0)));
  std::fprintf(stderr,
               "robot-guided calibration: %d stops (%d skipped), RMS reprojection %.3f / %.3f px, "
               "3D error over its box %.2f mm RMS, ball offset (%.1f, %.1f, %.1f) mm; %.0f s "
               "simulated in %.0f s\n",
               r.stops, r.skipped, r.solution.cameras.rms_left, r.solution.cameras.rms_right,
               r.triangulation_rms * 1e3, r.solution.ball_offset.x() * 1e3,
               r.solution.ball_offset.y() * 1e3, r.solution.ball_offset.z() * 1e3, r.duration,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return r.solution.cameras;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Grasp success rate of the whole system in simulated time.", "grasp_success"};
  Options o;
  app.add_option("--trials", o.trials, "trials per mode")->check(CLI::PositiveNumber);
  app.add_option("--seed", o.seed, "seeds every trial's draw");
  app.add_option("--threads", o.threads, "trials run in parallel")->check(CLI::PositiveNumber);
  app.add_flag("--no-render", o.no_render,
               "no images or blob tracking: a camera model (projected truth + pixel noise, "
               "--pixel-sigma) into the product's triangulation");
  app.add_flag("--no-prediction", o.only_baseline,
               "only the baseline (aim at the last measurement)");
  app.add_flag("--no-baseline", o.skip_baseline, "only with prediction");
  app.add_flag("--kalman", o.kalman,
               "also the Kalman baseline: a constant-velocity Kalman filter's forecast (and its "
               "estimated sigmas) in place of Burg's");
  app.add_option("--sweep", o.sweep,
                 "success against one quantity, --trials a point in every mode: interaction "
                 "(the C550's time per command, s), speed (rpm) or occlusion (s)")
      ->check(CLI::IsMember({"interaction", "speed", "occlusion"}));
  app.add_option("--points", o.points, "the sweep's values (default: its own list)");
  app.add_option("--out", o.out, "directory for a sweep's .md, .dat, .gp and .png");
  app.add_flag("--no-replan", o.no_replan,
               "never re-plan an approach once sent (grasp.max_replans 0), for comparison");
  app.add_flag("--verbose", o.verbose, "per-trial diagnostics");
  app.add_option("--trial", o.only,
                 "run only this trial of the draw (0 .. trials - 1), e.g. a miss --verbose listed; "
                 "with --verbose, also the machine's message when it sent the approach")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--occluded-fraction", o.occluded_fraction,
                 "fraction of trials with a total occlusion covering the close")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--warmup", o.warmup, "s of tracking before the earliest grasp command");
  app.add_option("--grasp-window", o.grasp_window,
                 "s: the grasp command is drawn uniformly in [warmup, warmup + this)");
  app.add_option("--frame-rate", o.frame_rate, "Hz: stereo frames (render + vision)");
  app.add_option("--pixel-sigma", o.pixel_sigma, "px per axis, --no-render");
  app.add_option("--selection", o.selection,
                 "which region vision takes for the ball: scored, or largest (the paper's rule, "
                 "its centroid)")
      ->check(CLI::IsMember({"scored", "largest"}));
  app.add_option("--calibration", o.calibration,
                 "the cameras vision triangulates with: robot (robot-guided calibration first, in "
                 "simulated time through the same driver, controller, cameras and tracker; the "
                 "lab's way) or true (the simulator's own cameras)")
      ->check(CLI::IsMember({"robot", "true"}));
  CLI11_PARSE(app, argc, argv);
  cv::setNumThreads(1);  // the trials are the parallelism
  spdlog::set_level(o.verbose ? spdlog::level::info : spdlog::level::err);  // the driver's log
  std::vector<Mode> modes;
  if (!o.only_baseline) modes.push_back(Mode::kPrediction);
  if (!o.skip_baseline || o.only_baseline) modes.push_back(Mode::kNoPrediction);
  if (o.kalman) modes.push_back(Mode::kKalman);
  try {
    if (o.calibration == "robot") o.cameras = calibrate(o);
    if (!o.sweep.empty()) {
      run_sweep(o, modes);
      return 0;
    }
    std::vector<ModeSummary> summaries;
    for (Mode m : modes) summaries.push_back(run_mode(o, m));
    print_table(o, summaries);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "grasp_success: %s\n", e.what());
    return 1;
  }
  return 0;
}
