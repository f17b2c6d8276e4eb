#include "logger/report.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "logger/log_reader.hpp"

#if __has_include("logger/channel_csv.hpp")
#include "logger/channel_csv.hpp"
#define SG_HAVE_CHANNEL_CSV 1
#endif
#if __has_include("logger/session_plots.hpp")
#include "logger/session_plots.hpp"
#define SG_HAVE_SESSION_PLOTS 1
#endif

namespace sg::logger {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// --- text helpers --------------------------------------------------------------------------

std::string num(double v, int decimals = 3) {
  if (std::isnan(v)) return "–";
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, v);
  return text;
}

std::string utc(int64_t utime) {
  const std::time_t secs = static_cast<std::time_t>(utime / 1'000'000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char text[64];
  std::snprintf(text, sizeof(text), "%04d-%02d-%02d %02d:%02d:%02d.%03d UTC", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec,
                static_cast<int>((utime / 1000) % 1000));
  return text;
}

std::string md_cell(std::string s) {
  for (char& c : s)
    if (c == '|' || c == '\n') c = ' ';
  return s;
}

Json j_num(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json j_quantiles(const Quantiles& q, double scale = 1) {
  Json j;
  j["count"] = q.count;
  j["mean"] = j_num(q.mean * scale);
  j["rms"] = j_num(q.rms * scale);
  j["min"] = j_num(q.min * scale);
  j["p50"] = j_num(q.p50 * scale);
  j["p95"] = j_num(q.p95 * scale);
  j["p99"] = j_num(q.p99 * scale);
  j["max"] = j_num(q.max * scale);
  return j;
}

}  // namespace

std::string default_report_dir(const std::string& log_path) {
  std::string base = log_path;
  const std::string ext = ".lcmlog";
  if (base.size() > ext.size() && base.compare(base.size() - ext.size(), ext.size(), ext) == 0)
    base.resize(base.size() - ext.size());
  return base + ".report";
}

// --- JSON ----------------------------------------------------------------------------------

namespace {

/// report.json's "log": the file, its events and time span, and the damage found in it.
Json j_log(const SessionSummary& s) {
  Json log;
  log["path"] = s.path;
  log["size_bytes"] = s.file_size;
  log["events"] = s.events;
  log["first_utime"] = s.first_utime;
  log["last_utime"] = s.last_utime;
  log["duration_s"] = s.duration_s;
  log["truncated"] = s.truncated;
  log["skipped_bytes"] = s.skipped_bytes;
  log["problem_count"] = s.problem_count;
  Json problems = Json::array();
  for (const LogProblem& p : s.problems)
    problems.push_back({{"kind", p.kind == LogProblem::Kind::kSkipped ? "skipped" : "truncated"},
                        {"offset", p.offset},
                        {"bytes", p.bytes},
                        {"text", p.text}});
  log["problems"] = problems;
  log["wrong_size"] = s.wrong_size;
  log["wrong_type"] = s.wrong_type;
  return log;
}

/// One entry of report.json's "channels": counts, rate, gaps and decoding of one channel.
Json j_channel(const ChannelSummary& c) {
  Json k;
  k["name"] = c.name;
  k["type"] = c.type;
  k["expected_type"] = c.expected_type;
  k["count"] = c.count;
  k["bytes"] = c.bytes;
  k["first_recv_utime"] = c.first_recv_utime;
  k["last_recv_utime"] = c.last_recv_utime;
  k["rate_hz"] = j_num(c.rate_hz);
  k["median_period_s"] = j_num(c.median_period_s);
  k["largest_gap_s"] = j_num(c.largest_gap_s);
  k["largest_gap_at_s"] = j_num(c.largest_gap_at_s);
  k["gaps_over_3x_median"] = c.gaps_over_3x;
  k["decoded"] = c.decoded;
  k["wrong_size"] = c.wrong_size;
  k["wrong_type"] = c.wrong_type;
  k["unknown_fingerprint"] = c.unknown_fingerprint;
  k["first_problem"] = c.first_problem;
  return k;
}

/// Channels that are not stereograsp's (or LCM's own): name, count and fingerprint of each.
Json j_unknown_list(const std::vector<UnknownChannel>& list) {
  Json a = Json::array();
  for (const UnknownChannel& u : list)
    a.push_back({{"name", u.name}, {"count", u.count}, {"fingerprint", u.fingerprint}});
  return a;
}

/// report.json's "cameras": per BLOB channel, frames, detections and time in each search mode.
Json j_cameras(const std::vector<CameraSummary>& list) {
  Json cameras = Json::object();
  for (const CameraSummary& c : list) {
    cameras[c.channel] = {{"frames", c.frames},
                          {"detected", c.detected},
                          {"detection_rate", j_num(c.detection_rate)},
                          {"tracking_frames", c.tracking_frames},
                          {"full_frame_frames", c.full_frame_frames},
                          {"tracking_s", c.tracking_s},
                          {"full_frame_s", c.full_frame_s}};
  }
  return cameras;
}

/// report.json's "triangulation": positions, the reprojection residual and the quality flags.
Json j_triangulation(const TriangulationSummary& t) {
  return {{"positions", t.positions},
          {"visible", t.visible},
          {"residual_px", j_quantiles(t.residual_px)},
          {"vs_truth_m", j_quantiles(t.vs_truth_m)},
          {"flag_behind_camera", t.behind_camera},
          {"flag_near_parallel_rays", t.near_parallel},
          {"flag_large_residual", t.large_residual}};
}

/// report.json's "latency_ms": per stage, receive time minus the message's own time.
Json j_latency(const std::vector<LatencySummary>& list) {
  Json latency = Json::object();
  for (const LatencySummary& l : list) {
    Json k = j_quantiles(l.ms);
    k["reference"] = l.reference;
    k["negative"] = l.negative;
    latency[l.stage] = k;
  }
  return latency;
}

/// report.json's "prediction": per horizon h, the error against the measurement and the truth.
Json j_prediction(const std::vector<HorizonSummary>& list) {
  Json prediction = Json::array();
  for (const HorizonSummary& h : list)
    prediction.push_back({{"h", h.h},
                          {"predictions", h.predictions},
                          {"vs_measurement_m", j_quantiles(h.vs_measurement)},
                          {"unmatched_measurement", h.unmatched_measurement},
                          {"vs_truth_m", j_quantiles(h.vs_truth)},
                          {"unmatched_truth", h.unmatched_truth}});
  return prediction;
}

/// report.json's "prediction_by_phase": per phase, its time and per horizon the errors there.
Json j_prediction_by_phase(const std::vector<PhasePrediction>& list) {
  Json phases = Json::array();
  for (const PhasePrediction& p : list) {
    Json horizons = Json::array();
    for (const PhaseHorizon& h : p.horizons)
      horizons.push_back({{"h", h.h},
                          {"vs_measurement_m", j_quantiles(h.vs_measurement)},
                          {"vs_truth_m", j_quantiles(h.vs_truth)}});
    phases.push_back({{"phase", p.key},
                      {"name", p.phase},
                      {"duration_s", j_num(p.duration_s)},
                      {"horizons", horizons}});
  }
  return phases;
}

/// report.json's "occlusions": totals and each episode with the prediction error in and after it.
Json j_occlusions(const OcclusionSummary& o) {
  Json episodes = Json::array();
  for (const OcclusionEpisode& e : o.episodes)
    episodes.push_back({{"start_s", e.start_s},
                        {"duration_s", e.duration_s},
                        {"gap", e.gap},
                        {"open_at_end", e.open_at_end},
                        {"occluded_trajectories", e.occluded_trajectories},
                        {"vs_truth_m", j_quantiles(e.vs_truth)},
                        {"after_vs_measurement_m", j_quantiles(e.after_vs_measurement)}});
  return {{"count", o.count},
          {"total_s", o.total_s},
          {"longest_s", o.longest_s},
          {"episodes", episodes}};
}

/// report.json's "arm": statuses, commands by mode, interaction times, rejections and errors.
Json j_arm(const ArmSummary& a) {
  return {{"statuses", a.statuses},           {"commands", a.commands},
          {"command_modes", a.command_modes}, {"interaction_s", j_quantiles(a.interaction_s)},
          {"rejections", a.rejections},       {"errors", a.errors}};
}

/// report.json's "grasp": outcomes, operator commands and the listed state changes.
Json j_grasp(const GraspSummary& g) {
  Json events = Json::array();
  for (const GraspEvent& e : g.events)
    events.push_back({{"t_s", e.t_s},
                      {"utime", e.utime},
                      {"state", e.state},
                      {"activity", e.activity},
                      {"action", e.action},
                      {"outcome", e.outcome},
                      {"message", e.message}});
  return {{"statuses", g.statuses}, {"event_count", g.event_count}, {"success", g.success},
          {"failed", g.failed},     {"aborted", g.aborted},         {"commands", g.commands},
          {"events", events}};
}

/// report.json's "processes": who published PROCESS_STATUS, their stops and silences, clocks.
Json j_processes(const ProcessesSummary& p) {
  Json processes = Json::array();
  for (const ProcessSummary& s : p.processes)
    processes.push_back({{"name", s.name},
                         {"host", s.host},
                         {"first_s", s.first_s},
                         {"last_s", s.last_s},
                         {"last_state", s.last_state},
                         {"bad", s.bad},
                         {"last_problem", s.last_problem},
                         {"vouched_as", s.vouched_as},
                         {"unvouched", s.unvouched},
                         {"refusals", s.refusals}});
  Json clocks = Json::array();
  for (const ProcessWatch::HostOffset& h : p.clocks)
    clocks.push_back({{"host", h.host},
                      {"known", h.known},
                      {"offset_us", h.offset_us},
                      {"error_us", h.error_us}});
  return {{"processes", processes},
          {"events", p.events},
          {"event_count", p.event_count},
          {"clock_reference", p.clock_reference},
          {"clocks", clocks},
          {"clock_warnings", p.clock_warnings}};
}

}  // namespace

std::string report_json(const SessionSummary& s) {
  Json j;
  j["log"] = j_log(s);
  Json channels = Json::array();
  for (const ChannelSummary& c : s.channels) channels.push_back(j_channel(c));
  j["channels"] = channels;
  j["unknown_channels"] = j_unknown_list(s.unknown);
  j["lcm_internal"] = j_unknown_list(s.lcm_internal);
  j["cameras"] = j_cameras(s.cameras);
  j["triangulation"] = j_triangulation(s.triangulation);
  j["latency_ms"] = j_latency(s.latency);
  j["histogram_bin_ratio"] = std::pow(10.0, 1.0 / 20);
  j["prediction"] = j_prediction(s.prediction);
  j["prediction_by_phase"] = j_prediction_by_phase(s.prediction_by_phase);
  j["occlusions"] = j_occlusions(s.occlusions);
  j["arm"] = j_arm(s.arm);
  j["grasp"] = j_grasp(s.grasp);
  j["processes"] = j_processes(s.processes);
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

// --- Markdown ------------------------------------------------------------------------------

namespace {

/// The title and the table of the log file, its events, start and duration.
void md_header(std::ostream& o, const SessionSummary& s) {
  o << "# Session report: " << fs::path(s.path).filename().string() << "\n\n";
  o << "| | |\n|---|---|\n";
  o << "| log | `" << s.path << "` (" << s.file_size << " bytes) |\n";
  o << "| events | " << s.events << " |\n";
  if (s.events > 0) {
    o << "| start | " << utc(s.first_utime) << " |\n";
    o << "| duration | " << num(s.duration_s, 1) << " s |\n";
  }
}

/// One line per kind of bad message on a channel; true if the channel has any.
bool md_channel_problems(std::ostream& o, const ChannelSummary& c) {
  if (c.wrong_size > 0)
    o << "- " << c.name << ": " << c.wrong_size
      << " message(s) of the wrong size; first: " << c.first_problem << "\n";
  if (c.wrong_type > 0)
    o << "- " << c.name << ": " << c.wrong_type
      << " message(s) of the wrong type; first: " << c.first_problem << "\n";
  if (c.unknown_fingerprint > 0 && !c.expected_type.empty())
    o << "- " << c.name << ": " << c.unknown_fingerprint
      << " message(s) with an unknown fingerprint\n";
  if (c.expected_type.empty() && c.type != "?")
    o << "- " << c.name << ": not a stereograsp channel name (its messages are " << c.type << ")\n";
  return (c.expected_type.empty() && c.type != "?") || c.wrong_size > 0 || c.wrong_type > 0 ||
         (c.unknown_fingerprint > 0 && !c.expected_type.empty());
}

/// "Problems": damaged stretches of the file, bad messages, unknown channels ("None." if none),
/// then LCM's own channels.
void md_problems(std::ostream& o, const SessionSummary& s) {
  o << "\n## Problems\n\n";
  bool any = false;
  for (const LogProblem& p : s.problems) {
    o << "- " << p.text << "\n";
    any = true;
  }
  if (s.problem_count > static_cast<int64_t>(s.problems.size()))
    o << "- ... and " << (s.problem_count - static_cast<int64_t>(s.problems.size()))
      << " more damaged stretches\n";
  for (const ChannelSummary& c : s.channels) any = md_channel_problems(o, c) || any;
  for (const UnknownChannel& u : s.unknown) {
    o << "- unknown channel " << u.name << ": " << u.count << " message(s), fingerprint "
      << (u.fingerprint.empty() ? "(too short)" : u.fingerprint) << "\n";
    any = true;
  }
  for (const std::string& w : s.processes.clock_warnings) {
    o << "- " << w << "\n";
    any = true;
  }
  for (const std::string& e : s.processes.events) {
    if (e.find("stopped beating") == std::string::npos) continue;
    o << "- " << e << "\n";
    any = true;
  }
  for (const ProcessSummary& p : s.processes.processes) {
    for (const std::string& r : p.refusals)
      o << "- " << md_cell(p.name)
        << " refused messages nobody it believes vouched for: " << md_cell(r) << "\n";
    any = any || !p.refusals.empty();
  }
  if (!any) o << "None.\n";
  for (const UnknownChannel& u : s.lcm_internal)
    o << "\nLCM's own: " << u.name << " (" << u.count << " message(s); normal on udpm).\n";
}

/// "Processes" (when any published PROCESS_STATUS): a row per process, the stops and silences,
/// and every host's clock against the reference host's.
void md_processes(std::ostream& o, const ProcessesSummary& p) {
  if (p.processes.empty()) return;
  o << "\n## Processes\n\n"
    << "| process | host | first s | last s | last state | vouched as | unvouched | bad messages "
       "| last problem |\n"
       "|---|---|---:|---:|---|---|---:|---:|---|\n";
  for (const ProcessSummary& s : p.processes)
    o << "| " << md_cell(s.name) << " | " << md_cell(s.host) << " | " << num(s.first_s, 1) << " | "
      << num(s.last_s, 1) << " | " << s.last_state << " | "
      << (s.vouched_as.empty() ? "(nobody: insecure)" : md_cell(s.vouched_as)) << " | "
      << s.unvouched << " | " << s.bad << " | " << md_cell(s.last_problem) << " |\n";
  if (!p.events.empty()) {
    o << "\n";
    for (const std::string& e : p.events) o << "- " << md_cell(e) << "\n";
    if (p.event_count > static_cast<int64_t>(p.events.size()))
      o << "- ... and " << (p.event_count - static_cast<int64_t>(p.events.size())) << " more\n";
  }
  o << "\nClocks, as the processes measured them from their heartbeats (NTP-style; docs/lab.md), "
       "against "
    << md_cell(p.clock_reference) << "'s:\n\n| host | offset ms | ± ms |\n|---|---:|---:|\n";
  for (const ProcessWatch::HostOffset& h : p.clocks)
    o << "| " << md_cell(h.host) << " | " << (h.known ? num(h.offset_us / 1e3, 1) : "unknown")
      << " | " << (h.known ? num(h.error_us / 1e3, 1) : "–") << " |\n";
}

/// "Channels": one row per channel with its type, count, rate, period, gaps and decoded count.
void md_channels(std::ostream& o, const std::vector<ChannelSummary>& channels) {
  o << "\n## Channels\n\n"
    << "| channel | type | count | rate Hz | median period ms | largest gap s (at s) | gaps > 3x "
       "median | decoded |\n|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const ChannelSummary& c : channels)
    o << "| " << md_cell(c.name) << " | " << c.type << " | " << c.count << " | "
      << num(c.rate_hz, 2) << " | " << num(c.median_period_s * 1e3, 1) << " | "
      << num(c.largest_gap_s, 3) << " (" << num(c.largest_gap_at_s, 1) << ") | " << c.gaps_over_3x
      << " | " << c.decoded << " |\n";
}

/// "Cameras" (when there are blobs): detection rate and time in each search mode per camera.
void md_cameras(std::ostream& o, const std::vector<CameraSummary>& cameras) {
  if (cameras.empty()) return;
  o << "\n## Cameras\n\n| camera | frames | detection rate | search window: frames, s | "
       "full frame: frames, s |\n|---|---:|---:|---:|---:|\n";
  for (const CameraSummary& c : cameras)
    o << "| " << c.channel << " | " << c.frames << " | " << num(c.detection_rate * 100, 1)
      << " % | " << c.tracking_frames << ", " << num(c.tracking_s, 1) << " | "
      << c.full_frame_frames << ", " << num(c.full_frame_s, 1) << " |\n";
}

/// "Triangulation" (when there are positions): visibility, reprojection residual and flags.
void md_triangulation(std::ostream& o, const TriangulationSummary& t) {
  if (t.positions <= 0) return;
  o << "\n## Triangulation\n\n"
    << t.visible << " of " << t.positions << " positions visible. Reprojection residual (px): mean "
    << num(t.residual_px.mean) << ", p50 " << num(t.residual_px.p50) << ", p95 "
    << num(t.residual_px.p95) << ", max " << num(t.residual_px.max) << ". Flags: behind camera "
    << t.behind_camera << ", near-parallel rays " << t.near_parallel << ", large residual "
    << t.large_residual << ".\n";
  const Quantiles& e = t.vs_truth_m;
  if (e.count > 0) {
    o << "\nAgainst the simulator's GROUND_TRUTH of the same frame (" << e.count
      << " positions), mm: p50 " << num(e.p50 * 1e3) << ", p95 " << num(e.p95 * 1e3) << ", RMS "
      << num(e.rms * 1e3) << ", max " << num(e.max * 1e3) << ".\n";
  }
}

/// "Latency" (when measured): per stage, receive time minus the message's own time.
void md_latency(std::ostream& o, const std::vector<LatencySummary>& latency) {
  if (latency.empty()) return;
  o << "\n## Latency\n\nReceive time minus the message's own time, milliseconds.\n\n"
    << "| stage | minus | count | p50 | p95 | p99 | max | negative |\n"
    << "|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const LatencySummary& l : latency)
    o << "| " << l.stage << " | " << l.reference << " | " << l.ms.count << " | " << num(l.ms.p50, 2)
      << " | " << num(l.ms.p95, 2) << " | " << num(l.ms.p99, 2) << " | " << num(l.ms.max, 2)
      << " | " << l.negative << " |\n";
}

/// "Prediction error" (when any horizon has predictions): error vs measurement and vs truth.
void md_prediction(std::ostream& o, const std::vector<HorizonSummary>& prediction) {
  bool predictions = false;
  for (const HorizonSummary& h : prediction) predictions = predictions || h.predictions > 0;
  if (!predictions) return;
  o << "\n## Prediction error\n\nDistance from each predicted point to the measurement "
       "(interpolated between the two that bracket its time) and to the ground truth, "
       "metres.\n\n| h | predictions | vs measurement: n, RMS, p95, max | unmatched | vs "
       "truth: n, RMS, p95, max | unmatched |\n|---:|---:|---|---:|---|---:|\n";
  for (const HorizonSummary& h : prediction)
    o << "| " << h.h << " | " << h.predictions << " | " << h.vs_measurement.count << ", "
      << num(h.vs_measurement.rms, 4) << ", " << num(h.vs_measurement.p95, 4) << ", "
      << num(h.vs_measurement.max, 4) << " | " << h.unmatched_measurement << " | "
      << h.vs_truth.count << ", " << num(h.vs_truth.rms, 4) << ", " << num(h.vs_truth.p95, 4)
      << ", " << num(h.vs_truth.max, 4) << " | " << h.unmatched_truth << " |\n";
}

/// One "n, RMS, p95, max" cell in millimetres ("–" for none).
std::string mm_cell(const Quantiles& q) {
  if (q.count == 0) return "–";
  return std::to_string(q.count) + ", " + num(q.rms * 1e3, 2) + ", " + num(q.p95 * 1e3, 2) + ", " +
         num(q.max * 1e3, 2);
}

/// "Prediction error by phase" (when any prediction was scored): a row per phase and horizon.
void md_prediction_by_phase(std::ostream& o, const std::vector<PhasePrediction>& phases) {
  bool scored = false;
  for (const PhasePrediction& p : phases)
    for (const PhaseHorizon& h : p.horizons)
      scored = scored || h.vs_measurement.count > 0 || h.vs_truth.count > 0;
  if (!scored) return;
  o << "\n## Prediction error by phase\n\nThe same errors, in millimetres, by the phase of the "
       "session that a prediction was made in and its target lies in (docs/logs.md, "
       "\"Phases\"): in the calibration and the carried phase the arm moves the ball; coasting: "
       "made on fed-back samples through an occlusion; across phases: made in one phase for a "
       "time in another.\n\n| phase | time s | h | vs measurement: n, RMS, p95, max | vs truth: "
       "n, RMS, p95, max |\n|---|---:|---:|---|---|\n";
  for (const PhasePrediction& p : phases) {
    bool any = false;
    for (const PhaseHorizon& h : p.horizons) {
      if (h.vs_measurement.count == 0 && h.vs_truth.count == 0) continue;
      any = true;
      o << "| " << p.phase << " | " << num(p.duration_s, 1) << " | " << h.h << " | "
        << mm_cell(h.vs_measurement) << " | " << mm_cell(h.vs_truth) << " |\n";
    }
    if (!any && p.duration_s > 0)  // a phase with no prediction scored: its time alone
      o << "| " << p.phase << " | " << num(p.duration_s, 1) << " | – | – | – |\n";
  }
}

/// "Occlusions": totals, then a row per episode with the prediction error in and after it.
void md_occlusions(std::ostream& o, const OcclusionSummary& occlusions) {
  o << "\n## Occlusions\n\n"
    << occlusions.count << " episode(s), " << num(occlusions.total_s, 2)
    << " s in all, the longest " << num(occlusions.longest_s, 2) << " s.\n";
  if (occlusions.episodes.empty()) return;
  o << "\n| start s | duration s | kind | occluded trajectories | error inside vs truth: n, "
       "RMS, max (m) | error in the next second vs measurement: n, RMS, max (m) |\n"
       "|---:|---:|---|---:|---|---|\n";
  for (const OcclusionEpisode& e : occlusions.episodes)
    o << "| " << num(e.start_s, 2) << " | " << num(e.duration_s, 2) << " | "
      << (e.gap ? "no messages" : "not visible") << (e.open_at_end ? " (open at end)" : "") << " | "
      << e.occluded_trajectories << " | " << e.vs_truth.count << ", " << num(e.vs_truth.rms, 4)
      << ", " << num(e.vs_truth.max, 4) << " | " << e.after_vs_measurement.count << ", "
      << num(e.after_vs_measurement.rms, 4) << ", " << num(e.after_vs_measurement.max, 4) << " |\n";
}

/// "Arm" (when the arm spoke or was spoken to): commands, statuses, interaction time, refusals.
void md_arm(std::ostream& o, const ArmSummary& arm) {
  if (arm.statuses <= 0 && arm.commands <= 0) return;
  const Quantiles& q = arm.interaction_s;
  o << "\n## Arm\n\n"
    << arm.commands << " command(s), " << arm.statuses
    << " status message(s). Interaction time (s): " << q.count << " interaction(s), p50 "
    << num(q.p50) << ", p95 " << num(q.p95) << ", max " << num(q.max) << ", mean " << num(q.mean)
    << ". Rejections " << arm.rejections << ", errors " << arm.errors << ".\n";
}

/// "Grasping" (when sg-grasp ran or was commanded): outcomes, commands, the state changes.
void md_grasping(std::ostream& o, const GraspSummary& grasp) {
  if (grasp.statuses <= 0 && grasp.commands.empty()) return;
  o << "\n## Grasping\n\nOutcomes: " << grasp.success << " success, " << grasp.failed << " failed, "
    << grasp.aborted << " aborted.";
  if (!grasp.commands.empty()) {
    o << " Commands:";
    for (const auto& [name, n] : grasp.commands) o << " " << name << " " << n << ";";
  }
  o << "\n\n| t s | state | activity | last action | outcome | message |\n"
       "|---:|---|---|---|---|---|\n";
  for (const GraspEvent& e : grasp.events)
    o << "| " << num(e.t_s, 2) << " | " << e.state << " | " << e.activity << " | " << e.action
      << " | " << e.outcome << " | " << md_cell(e.message) << " |\n";
  if (grasp.event_count > static_cast<int64_t>(grasp.events.size()))
    o << "\n(" << grasp.event_count - static_cast<int64_t>(grasp.events.size())
      << " later events not listed.)\n";
}

/// "Files" (when any were written): PNGs shown inline, the others listed.
void md_files(std::ostream& o, const std::vector<std::string>& files) {
  if (files.empty()) return;
  o << "\n## Files\n\n";
  for (const std::string& f : files) {
    if (f.size() > 4 && f.compare(f.size() - 4, 4, ".png") == 0) {
      o << "![" << fs::path(f).stem().string() << "](" << f << ")\n\n";
    } else {
      o << "- " << f << "\n";
    }
  }
}

}  // namespace

std::string report_markdown(const SessionSummary& s, const std::vector<std::string>& files) {
  std::ostringstream o;
  md_header(o, s);
  md_problems(o, s);
  md_processes(o, s.processes);
  md_channels(o, s.channels);
  md_cameras(o, s.cameras);
  md_triangulation(o, s.triangulation);
  md_latency(o, s.latency);
  md_prediction(o, s.prediction);
  md_prediction_by_phase(o, s.prediction_by_phase);
  md_occlusions(o, s.occlusions);
  md_arm(o, s.arm);
  md_grasping(o, s.grasp);
  md_files(o, files);
  o << "\nPercentiles are the largest value seen in the log-spaced histogram bin that holds "
       "them: at most 12 % above the true value (20 bins a decade; interaction times 200 a "
       "decade, 1.2 %), exact when the bin holds one value. Means, RMS, minima and maxima are "
       "exact.\n";
  return o.str();
}

std::string summary_text(const SessionSummary& s) {
  std::ostringstream o;
  o << s.events << " events in " << num(s.duration_s, 1) << " s, " << s.channels.size()
    << " channel(s)";
  if (!s.unknown.empty()) o << ", " << s.unknown.size() << " unknown";
  o << "\n";
  for (const LogProblem& p : s.problems) o << "problem: " << p.text << "\n";
  if (s.wrong_size > 0) o << "problem: " << s.wrong_size << " message(s) of the wrong size\n";
  if (s.wrong_type > 0) o << "problem: " << s.wrong_type << " message(s) of the wrong type\n";
  for (const UnknownChannel& u : s.unknown)
    o << "unknown channel: " << u.name << " (" << u.count << ")\n";
  for (const std::string& w : s.processes.clock_warnings) o << "problem: " << w << "\n";
  for (const std::string& e : s.processes.events)
    if (e.find("stopped beating") != std::string::npos) o << "problem: " << e << "\n";
  if (!s.processes.processes.empty())
    o << "processes: " << s.processes.processes.size() << " on " << s.processes.clocks.size()
      << " host(s)\n";
  const TriangulationSummary& t = s.triangulation;
  if (t.visible > 0) o << "triangulation: residual p50 " << num(t.residual_px.p50, 3) << " px";
  if (t.visible > 0 && t.vs_truth_m.count > 0)
    o << ", " << num(t.vs_truth_m.p50 * 1e3, 2) << " mm p50 from the truth (" << t.vs_truth_m.count
      << " positions)";
  if (t.visible > 0) o << "\n";
  for (const HorizonSummary& h : s.prediction)
    if (h.vs_measurement.count > 0 || h.vs_truth.count > 0)
      o << "prediction h=" << h.h << ": RMS " << num(h.vs_measurement.rms, 4)
        << " m vs measurement, " << num(h.vs_truth.rms, 4) << " m vs truth\n";
  for (const PhasePrediction& p : s.prediction_by_phase) {
    if (p.key != "tracking") continue;
    for (const PhaseHorizon& h : p.horizons)
      if (h.vs_measurement.count > 0 || h.vs_truth.count > 0)
        o << "prediction h=" << h.h << " while tracking: RMS " << num(h.vs_measurement.rms * 1e3, 2)
          << " mm vs measurement, " << num(h.vs_truth.rms * 1e3, 2) << " mm vs truth\n";
  }
  if (s.occlusions.count > 0)
    o << "occlusions: " << s.occlusions.count << ", longest " << num(s.occlusions.longest_s, 2)
      << " s\n";
  if (s.grasp.success + s.grasp.failed + s.grasp.aborted > 0)
    o << "grasps: " << s.grasp.success << " success, " << s.grasp.failed << " failed, "
      << s.grasp.aborted << " aborted\n";
  return o.str();
}

// --- the pass ------------------------------------------------------------------------------

namespace {

/// The result with its directory: options.out_dir, or LOG.report beside the log; created.
ReportResult open_report_dir(const std::string& log_path, const ReportOptions& options) {
  ReportResult r;
  r.dir = options.out_dir.empty() ? default_report_dir(log_path) : options.out_dir;
  std::error_code ec;
  fs::create_directories(r.dir, ec);
  if (ec) throw LogReadError(r.dir + ": cannot create the report directory: " + ec.message());
  return r;
}

/// A file with bytes but not one event is not an LCM log: removes the (still empty) report
/// directory and throws.
void refuse_if_not_a_log(const LogReader& reader, const std::string& log_path,
                         const std::string& dir) {
  if (reader.events() == 0 && reader.file_size() > 0) {
    std::error_code ec;
    fs::remove(dir, ec);  // only when still empty
    throw LogReadError(log_path + ": not an LCM log (no event in " +
                       std::to_string(reader.file_size()) + " bytes)");
  }
}

/// Reads every event into `stats` (and, when asked, a CSV per channel), fills r.summary and
/// returns the CSV files written, relative to r.dir.
std::vector<std::string> summarize_log(LogReader& reader, SessionStats& stats,
                                       const std::string& log_path, const ReportOptions& options,
                                       ReportResult& r) {
#ifdef SG_HAVE_CHANNEL_CSV
  std::unique_ptr<ChannelCsv> csv;
  if (options.csv) {
    r.csv_dir = r.dir + "/csv";
    csv = std::make_unique<ChannelCsv>(r.csv_dir);
  }
#else
  // TODO(channel_csv): logger/channel_csv.hpp is not in this build; no CSV written.
  if (options.csv) r.notes.push_back("CSV not written: this build has no logger/channel_csv");
#endif
  LogRecord event;
  while (reader.next(event)) {
    stats.add(event);
#ifdef SG_HAVE_CHANNEL_CSV
    if (csv) csv->add(event.channel, event.recv_utime, event.data, event.size);
#endif
  }
  stats.finish(reader);
  refuse_if_not_a_log(reader, log_path, r.dir);
  r.summary = stats.summary();
  r.summary.path = log_path;
  std::vector<std::string> files;
#ifdef SG_HAVE_CHANNEL_CSV
  if (csv) {
    csv->flush();
    for (const std::string& f : csv->files()) files.push_back(fs::relative(f, r.dir).string());
  }
#endif
  return files;
}

/// Draws the session's plots into r.dir and adds their names to `files`; without gnuplot (or
/// with gnuplot failing) only the plots are skipped, and a note says why.
void draw_plots(const SessionStats& stats, ReportResult& r, std::vector<std::string>& files) {
#ifdef SG_HAVE_SESSION_PLOTS
  try {
    for (const std::string& png : write_session_plots(stats.plot_data(), r.dir))
      files.push_back(fs::path(png).filename().string());
    r.plots_written = true;
  } catch (const PlotError& e) {
    r.notes.push_back(std::string("plots skipped: ") + e.what());
  }
#else
  // TODO(session_plots): logger/session_plots.hpp is not in this build; no plots drawn.
  (void)stats, (void)files;
  r.notes.push_back("plots not drawn: this build has no logger/session_plots");
#endif
}

/// Writes `text` to `path`, or throws naming the file.
void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) throw LogReadError(path + ": cannot be written");
}

}  // namespace

ReportResult make_report(const std::string& log_path, const ReportOptions& options) {
  LogReader reader(log_path);
  ReportResult r = open_report_dir(log_path, options);
  StatsOptions stats_options;
  stats_options.horizons = options.horizons;
  SessionStats stats(stats_options);
  if (options.progress) reader.set_progress(options.progress);
  std::vector<std::string> files = summarize_log(reader, stats, log_path, options, r);
  if (options.plots) draw_plots(stats, r, files);
  r.markdown_path = r.dir + "/report.md";
  r.json_path = r.dir + "/report.json";
  write_text(r.markdown_path, report_markdown(r.summary, files));
  write_text(r.json_path, report_json(r.summary));
  return r;
}

}  // namespace sg::logger
