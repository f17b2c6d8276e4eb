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

std::string report_json(const SessionSummary& s) {
  Json j;
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
  j["log"] = log;

  Json channels = Json::array();
  for (const ChannelSummary& c : s.channels) {
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
    channels.push_back(k);
  }
  j["channels"] = channels;
  auto unknown_list = [](const std::vector<UnknownChannel>& list) {
    Json a = Json::array();
    for (const UnknownChannel& u : list)
      a.push_back({{"name", u.name}, {"count", u.count}, {"fingerprint", u.fingerprint}});
    return a;
  };
  j["unknown_channels"] = unknown_list(s.unknown);
  j["lcm_internal"] = unknown_list(s.lcm_internal);

  Json cameras = Json::object();
  for (const CameraSummary& c : s.cameras) {
    cameras[c.channel] = {{"frames", c.frames},
                          {"detected", c.detected},
                          {"detection_rate", j_num(c.detection_rate)},
                          {"tracking_frames", c.tracking_frames},
                          {"full_frame_frames", c.full_frame_frames},
                          {"tracking_s", c.tracking_s},
                          {"full_frame_s", c.full_frame_s}};
  }
  j["cameras"] = cameras;

  const TriangulationSummary& t = s.triangulation;
  j["triangulation"] = {{"positions", t.positions},
                        {"visible", t.visible},
                        {"residual_px", j_quantiles(t.residual_px)},
                        {"flag_behind_camera", t.behind_camera},
                        {"flag_near_parallel_rays", t.near_parallel},
                        {"flag_large_residual", t.large_residual}};

  Json latency = Json::object();
  for (const LatencySummary& l : s.latency) {
    Json k = j_quantiles(l.ms);
    k["reference"] = l.reference;
    k["negative"] = l.negative;
    latency[l.stage] = k;
  }
  j["latency_ms"] = latency;
  j["histogram_bin_ratio"] = std::pow(10.0, 1.0 / 20);

  Json prediction = Json::array();
  for (const HorizonSummary& h : s.prediction)
    prediction.push_back({{"h", h.h},
                          {"predictions", h.predictions},
                          {"vs_measurement_m", j_quantiles(h.vs_measurement)},
                          {"unmatched_measurement", h.unmatched_measurement},
                          {"vs_truth_m", j_quantiles(h.vs_truth)},
                          {"unmatched_truth", h.unmatched_truth}});
  j["prediction"] = prediction;

  Json episodes = Json::array();
  for (const OcclusionEpisode& e : s.occlusions.episodes)
    episodes.push_back({{"start_s", e.start_s},
                        {"duration_s", e.duration_s},
                        {"gap", e.gap},
                        {"open_at_end", e.open_at_end},
                        {"occluded_trajectories", e.occluded_trajectories},
                        {"vs_truth_m", j_quantiles(e.vs_truth)},
                        {"after_vs_measurement_m", j_quantiles(e.after_vs_measurement)}});
  j["occlusions"] = {{"count", s.occlusions.count},
                     {"total_s", s.occlusions.total_s},
                     {"longest_s", s.occlusions.longest_s},
                     {"episodes", episodes}};

  j["arm"] = {
      {"statuses", s.arm.statuses},           {"commands", s.arm.commands},
      {"command_modes", s.arm.command_modes}, {"interaction_s", j_quantiles(s.arm.interaction_s)},
      {"rejections", s.arm.rejections},       {"errors", s.arm.errors}};

  Json events = Json::array();
  for (const GraspEvent& e : s.grasp.events)
    events.push_back({{"t_s", e.t_s},
                      {"utime", e.utime},
                      {"state", e.state},
                      {"activity", e.activity},
                      {"action", e.action},
                      {"outcome", e.outcome},
                      {"message", e.message}});
  j["grasp"] = {{"statuses", s.grasp.statuses},
                {"event_count", s.grasp.event_count},
                {"success", s.grasp.success},
                {"failed", s.grasp.failed},
                {"aborted", s.grasp.aborted},
                {"commands", s.grasp.commands},
                {"events", events}};
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

// --- Markdown ------------------------------------------------------------------------------

std::string report_markdown(const SessionSummary& s, const std::vector<std::string>& files) {
  std::ostringstream o;
  o << "# Session report: " << fs::path(s.path).filename().string() << "\n\n";
  o << "| | |\n|---|---|\n";
  o << "| log | `" << s.path << "` (" << s.file_size << " bytes) |\n";
  o << "| events | " << s.events << " |\n";
  if (s.events > 0) {
    o << "| start | " << utc(s.first_utime) << " |\n";
    o << "| duration | " << num(s.duration_s, 1) << " s |\n";
  }
  o << "\n## Problems\n\n";
  bool any = false;
  for (const LogProblem& p : s.problems) {
    o << "- " << p.text << "\n";
    any = true;
  }
  if (s.problem_count > static_cast<int64_t>(s.problems.size()))
    o << "- ... and " << (s.problem_count - static_cast<int64_t>(s.problems.size()))
      << " more damaged stretches\n";
  for (const ChannelSummary& c : s.channels) {
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
      o << "- " << c.name << ": not a stereograsp channel name (its messages are " << c.type
        << ")\n";
    any = any || (c.expected_type.empty() && c.type != "?") || c.wrong_size > 0 ||
          c.wrong_type > 0 || (c.unknown_fingerprint > 0 && !c.expected_type.empty());
  }
  for (const UnknownChannel& u : s.unknown) {
    o << "- unknown channel " << u.name << ": " << u.count << " message(s), fingerprint "
      << (u.fingerprint.empty() ? "(too short)" : u.fingerprint) << "\n";
    any = true;
  }
  if (!any) o << "None.\n";
  for (const UnknownChannel& u : s.lcm_internal)
    o << "\nLCM's own: " << u.name << " (" << u.count << " message(s); normal on udpm).\n";

  o << "\n## Channels\n\n"
    << "| channel | type | count | rate Hz | median period ms | largest gap s (at s) | gaps > 3x "
       "median | decoded |\n|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const ChannelSummary& c : s.channels)
    o << "| " << md_cell(c.name) << " | " << c.type << " | " << c.count << " | "
      << num(c.rate_hz, 2) << " | " << num(c.median_period_s * 1e3, 1) << " | "
      << num(c.largest_gap_s, 3) << " (" << num(c.largest_gap_at_s, 1) << ") | " << c.gaps_over_3x
      << " | " << c.decoded << " |\n";

  if (!s.cameras.empty()) {
    o << "\n## Cameras\n\n| camera | frames | detection rate | search window: frames, s | "
         "full frame: frames, s |\n|---|---:|---:|---:|---:|\n";
    for (const CameraSummary& c : s.cameras)
      o << "| " << c.channel << " | " << c.frames << " | " << num(c.detection_rate * 100, 1)
        << " % | " << c.tracking_frames << ", " << num(c.tracking_s, 1) << " | "
        << c.full_frame_frames << ", " << num(c.full_frame_s, 1) << " |\n";
  }

  const TriangulationSummary& t = s.triangulation;
  if (t.positions > 0) {
    o << "\n## Triangulation\n\n"
      << t.visible << " of " << t.positions
      << " positions visible. Reprojection residual (px): mean " << num(t.residual_px.mean)
      << ", p50 " << num(t.residual_px.p50) << ", p95 " << num(t.residual_px.p95) << ", max "
      << num(t.residual_px.max) << ". Flags: behind camera " << t.behind_camera
      << ", near-parallel rays " << t.near_parallel << ", large residual " << t.large_residual
      << ".\n";
  }

  if (!s.latency.empty()) {
    o << "\n## Latency\n\nReceive time minus the message's own time, milliseconds.\n\n"
      << "| stage | minus | count | p50 | p95 | p99 | max | negative |\n"
      << "|---|---|---:|---:|---:|---:|---:|---:|\n";
    for (const LatencySummary& l : s.latency)
      o << "| " << l.stage << " | " << l.reference << " | " << l.ms.count << " | "
        << num(l.ms.p50, 2) << " | " << num(l.ms.p95, 2) << " | " << num(l.ms.p99, 2) << " | "
        << num(l.ms.max, 2) << " | " << l.negative << " |\n";
  }

  bool predictions = false;
  for (const HorizonSummary& h : s.prediction) predictions = predictions || h.predictions > 0;
  if (predictions) {
    o << "\n## Prediction error\n\nDistance from each predicted point to the measurement "
         "(interpolated between the two that bracket its time) and to the ground truth, "
         "metres.\n\n| h | predictions | vs measurement: n, RMS, p95, max | unmatched | vs "
         "truth: n, RMS, p95, max | unmatched |\n|---:|---:|---|---:|---|---:|\n";
    for (const HorizonSummary& h : s.prediction)
      o << "| " << h.h << " | " << h.predictions << " | " << h.vs_measurement.count << ", "
        << num(h.vs_measurement.rms, 4) << ", " << num(h.vs_measurement.p95, 4) << ", "
        << num(h.vs_measurement.max, 4) << " | " << h.unmatched_measurement << " | "
        << h.vs_truth.count << ", " << num(h.vs_truth.rms, 4) << ", " << num(h.vs_truth.p95, 4)
        << ", " << num(h.vs_truth.max, 4) << " | " << h.unmatched_truth << " |\n";
  }

  o << "\n## Occlusions\n\n"
    << s.occlusions.count << " episode(s), " << num(s.occlusions.total_s, 2)
    << " s in all, the longest " << num(s.occlusions.longest_s, 2) << " s.\n";
  if (!s.occlusions.episodes.empty()) {
    o << "\n| start s | duration s | kind | occluded trajectories | error inside vs truth: n, "
         "RMS, max (m) | error in the next second vs measurement: n, RMS, max (m) |\n"
         "|---:|---:|---|---:|---|---|\n";
    for (const OcclusionEpisode& e : s.occlusions.episodes)
      o << "| " << num(e.start_s, 2) << " | " << num(e.duration_s, 2) << " | "
        << (e.gap ? "no messages" : "not visible") << (e.open_at_end ? " (open at end)" : "")
        << " | " << e.occluded_trajectories << " | " << e.vs_truth.count << ", "
        << num(e.vs_truth.rms, 4) << ", " << num(e.vs_truth.max, 4) << " | "
        << e.after_vs_measurement.count << ", " << num(e.after_vs_measurement.rms, 4) << ", "
        << num(e.after_vs_measurement.max, 4) << " |\n";
  }

  if (s.arm.statuses > 0 || s.arm.commands > 0) {
    const Quantiles& q = s.arm.interaction_s;
    o << "\n## Arm\n\n"
      << s.arm.commands << " command(s), " << s.arm.statuses
      << " status message(s). Interaction time (s): " << q.count << " interaction(s), p50 "
      << num(q.p50) << ", p95 " << num(q.p95) << ", max " << num(q.max) << ", mean " << num(q.mean)
      << ". Rejections " << s.arm.rejections << ", errors " << s.arm.errors << ".\n";
  }

  if (s.grasp.statuses > 0 || !s.grasp.commands.empty()) {
    o << "\n## Grasping\n\nOutcomes: " << s.grasp.success << " success, " << s.grasp.failed
      << " failed, " << s.grasp.aborted << " aborted.";
    if (!s.grasp.commands.empty()) {
      o << " Commands:";
      for (const auto& [name, n] : s.grasp.commands) o << " " << name << " " << n << ";";
    }
    o << "\n\n| t s | state | activity | last action | outcome | message |\n"
         "|---:|---|---|---|---|---|\n";
    for (const GraspEvent& e : s.grasp.events)
      o << "| " << num(e.t_s, 2) << " | " << e.state << " | " << e.activity << " | " << e.action
        << " | " << e.outcome << " | " << md_cell(e.message) << " |\n";
    if (s.grasp.event_count > static_cast<int64_t>(s.grasp.events.size()))
      o << "\n(" << s.grasp.event_count - static_cast<int64_t>(s.grasp.events.size())
        << " later events not listed.)\n";
  }

  if (!files.empty()) {
    o << "\n## Files\n\n";
    for (const std::string& f : files) {
      if (f.size() > 4 && f.compare(f.size() - 4, 4, ".png") == 0) {
        o << "![" << fs::path(f).stem().string() << "](" << f << ")\n\n";
      } else {
        o << "- " << f << "\n";
      }
    }
  }
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
  for (const HorizonSummary& h : s.prediction)
    if (h.vs_measurement.count > 0 || h.vs_truth.count > 0)
      o << "prediction h=" << h.h << ": RMS " << num(h.vs_measurement.rms, 4)
        << " m vs measurement, " << num(h.vs_truth.rms, 4) << " m vs truth\n";
  if (s.occlusions.count > 0)
    o << "occlusions: " << s.occlusions.count << ", longest " << num(s.occlusions.longest_s, 2)
      << " s\n";
  if (s.grasp.success + s.grasp.failed + s.grasp.aborted > 0)
    o << "grasps: " << s.grasp.success << " success, " << s.grasp.failed << " failed, "
      << s.grasp.aborted << " aborted\n";
  return o.str();
}

// --- the pass ------------------------------------------------------------------------------

ReportResult make_report(const std::string& log_path, const ReportOptions& options) {
  LogReader reader(log_path);
  ReportResult r;
  r.dir = options.out_dir.empty() ? default_report_dir(log_path) : options.out_dir;
  std::error_code ec;
  fs::create_directories(r.dir, ec);
  if (ec) throw LogReadError(r.dir + ": cannot create the report directory: " + ec.message());

  StatsOptions stats_options;
  stats_options.horizons = options.horizons;
  SessionStats stats(stats_options);
  if (options.progress) reader.set_progress(options.progress);

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
  if (reader.events() == 0 && reader.file_size() > 0) {
    fs::remove(r.dir, ec);  // only when still empty
    throw LogReadError(log_path + ": not an LCM log (no event in " +
                       std::to_string(reader.file_size()) + " bytes)");
  }
  r.summary = stats.summary();
  r.summary.path = log_path;

  std::vector<std::string> files;
#ifdef SG_HAVE_CHANNEL_CSV
  if (csv) {
    csv->flush();
    for (const std::string& f : csv->files()) files.push_back(fs::relative(f, r.dir).string());
  }
#endif
  if (options.plots) {
#ifdef SG_HAVE_SESSION_PLOTS
    try {  // no gnuplot, or gnuplot failing, skips the plots only: one note says why
      for (const std::string& png : write_session_plots(stats.plot_data(), r.dir))
        files.push_back(fs::path(png).filename().string());
      r.plots_written = true;
    } catch (const PlotError& e) {
      r.notes.push_back(std::string("plots skipped: ") + e.what());
    }
#else
    // TODO(session_plots): logger/session_plots.hpp is not in this build; no plots drawn.
    r.notes.push_back("plots not drawn: this build has no logger/session_plots");
#endif
  }

  r.markdown_path = r.dir + "/report.md";
  r.json_path = r.dir + "/report.json";
  auto write = [](const std::string& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
    out.close();
    if (!out) throw LogReadError(path + ": cannot be written");
  };
  write(r.markdown_path, report_markdown(r.summary, files));
  write(r.json_path, report_json(r.summary));
  return r;
}

}  // namespace sg::logger
