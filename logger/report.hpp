#pragma once

/// A session report from an lcm-logger file: one streaming pass that feeds the statistics, the
/// CSV per channel and the plots, then report.md (for people) and report.json (the same figures
/// for programs) in an output directory.
///
///     sg::logger::ReportOptions options;                 // DIR = LOG without .lcmlog + ".report"
///     options.progress = [](int64_t pos, int64_t size) { show(pos, size); };
///     const sg::logger::ReportResult r = sg::logger::make_report("run.lcmlog", options);
///     std::cout << sg::logger::summary_text(r.summary) << r.markdown_path << "\n";
///
/// Layout: DIR/report.md, DIR/report.json, DIR/csv/<CHANNEL>.csv, DIR/xy.png, y_time.png,
/// latency.png, arm.png (the CSV and plot writers are logger/channel_csv and
/// logger/session_plots; a build without them writes the reports alone and says so).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "logger/session_stats.hpp"

namespace sg::logger {

struct ReportOptions {
  std::string out_dir;  ///< "" for default_report_dir(log)
  bool plots = true;
  bool csv = true;
  std::vector<int> horizons = {1, 4, 16};
  /// Called with (file position, file size) as the pass goes on.
  std::function<void(int64_t, int64_t)> progress;
};

struct ReportResult {
  SessionSummary summary;
  std::string dir, markdown_path, json_path;
  std::string csv_dir;  ///< "" when no CSV was written
  bool plots_written = false;
  std::vector<std::string> notes;  ///< what was not written and why
};

/// LOG without its .lcmlog extension, plus ".report".
std::string default_report_dir(const std::string& log_path);

/// Reads the log once and writes everything. Throws LogReadError for a file that cannot be read
/// or holds no event at all; a damaged log gives a report that lists the damage.
ReportResult make_report(const std::string& log_path, const ReportOptions& options);

/// The report for people (Markdown tables).
std::string report_markdown(const SessionSummary& s, const std::vector<std::string>& files = {});
/// The same figures for programs (JSON; NaN is null).
std::string report_json(const SessionSummary& s);
/// A few lines for the terminal.
std::string summary_text(const SessionSummary& s);

}  // namespace sg::logger
