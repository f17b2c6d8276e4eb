// sg-report: a session's report from an lcm-logger file, in one streaming pass (docs/logs.md):
// report.md, report.json, a CSV per channel and PNG plots; one channel as CSV; the channel list.
//
//   sg-report run.lcmlog                        # into run.report/ (report.md, .json, csv/, *.png)
//   sg-report run.lcmlog --out DIR --no-plots --no-csv --horizons 1,4,16 --quiet
//   sg-report export run.lcmlog --channel OBJECT_POSITION --csv [--out FILE]   # stdout by default
//   sg-report channels run.lcmlog               # NAME TYPE COUNT FIRST_UTIME LAST_UTIME per line

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>

#include "common/program.hpp"
#include "logger/log_reader.hpp"
#include "logger/report.hpp"
#include "logger/session_stats.hpp"

#if __has_include("logger/channel_csv.hpp")
#include "logger/channel_csv.hpp"
#define SG_HAVE_CHANNEL_CSV 1
#endif

namespace {

using sg::logger::LogReader;
using sg::logger::LogRecord;

/// Progress on stderr: a line redrawn in place on a terminal, else a line per 10 % for big logs.
std::function<void(int64_t, int64_t)> progress_printer(bool quiet) {
  if (quiet) return {};
  const bool tty = ::isatty(STDERR_FILENO) != 0;
  auto last_tenth = std::make_shared<int>(-1);
  return [tty, last_tenth](int64_t pos, int64_t size) {
    if (size <= 0) return;
    const int percent = static_cast<int>(100 * pos / size);
    if (tty) {
      std::fprintf(stderr, "\rsg-report: reading %3d %% (%.1f of %.1f MB)", percent, pos / 1e6,
                   size / 1e6);
      if (pos >= size) std::fputc('\n', stderr);
    } else if (size > (64 << 20) && percent / 10 != *last_tenth) {
      *last_tenth = percent / 10;
      std::fprintf(stderr, "sg-report: reading %d %%\n", percent);
    }
  };
}

void warn_problems(const LogReader& reader) {
  for (const auto& p : reader.problems()) std::fprintf(stderr, "sg-report: %s\n", p.text.c_str());
}

int run_report(const std::string& log, const std::string& out, bool no_plots, bool no_csv,
               const std::vector<int>& horizons, bool quiet) {
  sg::logger::ReportOptions options;
  options.out_dir = out;
  options.plots = !no_plots;
  options.csv = !no_csv;
  options.horizons = horizons;
  options.progress = progress_printer(quiet);
  const sg::logger::ReportResult r = sg::logger::make_report(log, options);
  if (!quiet) std::cout << sg::logger::summary_text(r.summary);
  for (const std::string& note : r.notes) std::cout << "note: " << note << "\n";
  std::cout << "report: " << r.markdown_path << "\n"
            << "json: " << r.json_path << "\n";
  if (!r.csv_dir.empty()) std::cout << "csv: " << r.csv_dir << "/\n";
  if (r.plots_written) std::cout << "plots: " << r.dir << "/*.png\n";
  return 0;
}

int run_export(const std::string& log, const std::string& channel, const std::string& out_path) {
#ifdef SG_HAVE_CHANNEL_CSV
  LogReader reader(log);
  std::ofstream file;
  if (!out_path.empty()) {
    file.open(out_path);
    if (!file) throw std::runtime_error(out_path + ": cannot be written");
  }
  std::ostream& out = out_path.empty() ? std::cout : file;
  sg::logger::CsvWriter writer;
  int64_t seen = 0, refused = 0;
  LogRecord e;
  while (reader.next(e)) {
    if (e.channel != channel) continue;
    ++seen;
    if (!writer.write(out, e.recv_utime, e.data, e.size)) ++refused;
  }
  out.flush();
  warn_problems(reader);
  if (seen == 0) throw std::runtime_error("channel '" + channel + "' is not in " + log);
  if (writer.rows() == 0)
    throw std::runtime_error("channel '" + channel + "' holds no stereograsp message (" +
                             std::to_string(seen) + " message(s) of another type)");
  if (refused > 0)
    std::fprintf(stderr, "sg-report: %lld message(s) on %s not exported (wrong size or type)\n",
                 static_cast<long long>(refused), channel.c_str());
  if (!out_path.empty())
    std::fprintf(stderr, "sg-report: %lld row(s) of %s written to %s\n",
                 static_cast<long long>(writer.rows()), writer.type_name().c_str(),
                 out_path.c_str());
  return 0;
#else
  // TODO(channel_csv): export needs logger/channel_csv.hpp.
  (void)log, (void)channel, (void)out_path;
  throw std::runtime_error("export is not in this build (no logger/channel_csv)");
#endif
}

int run_channels(const std::string& log) {
  struct Entry {
    std::string type;
    int64_t count = 0, first = 0, last = 0;
  };
  std::map<std::string, Entry> channels;
  LogReader reader(log);
  LogRecord e;
  while (reader.next(e)) {
    Entry& c = channels[e.channel];
    if (c.count++ == 0) c.first = e.recv_utime;
    c.last = e.recv_utime;
    if (c.type.empty() || c.type == "?") {
      c.type = sg::logger::type_of_message(e.data, e.size);
      if (c.type.empty()) c.type = e.channel == "LCM_SELF_TEST" ? "lcm_self_test" : "?";
    }
  }
  warn_problems(reader);
  if (reader.events() == 0 && reader.file_size() > 0)
    throw std::runtime_error(log + ": not an LCM log (no event in " +
                             std::to_string(reader.file_size()) + " bytes)");
  for (const auto& [name, c] : channels)
    std::printf("%s %s %lld %lld %lld\n", name.c_str(), c.type.c_str(),
                static_cast<long long>(c.count), static_cast<long long>(c.first),
                static_cast<long long>(c.last));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Session report from an lcm-logger file: report.md, report.json, CSV, plots",
               "sg-report"};
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return std::string("sg-report: error: ") + e.what() + " (see --help)\n";
  });
  app.require_subcommand(0, 1);
  std::string log, out;
  bool no_plots = false, no_csv = false, quiet = false;
  std::vector<int> horizons = {1, 4, 16};
  app.add_option("LOG", log, "lcm-logger file");
  app.add_option("--out", out, "output directory (default: LOG without .lcmlog + .report)");
  app.add_flag("--no-plots", no_plots, "do not draw the PNG plots");
  app.add_flag("--no-csv", no_csv, "do not write a CSV per channel");
  app.add_option("--horizons", horizons, "prediction steps to score, e.g. 1,4,16")
      ->delimiter(',')
      ->check(CLI::Range(1, 10000));
  app.add_flag("--quiet", quiet, "no progress and no summary, only the paths");

  CLI::App* exp = app.add_subcommand("export", "one channel as CSV (stdout unless --out)");
  std::string exp_log, exp_channel, exp_out;
  bool exp_csv = false;
  exp->add_option("LOG", exp_log, "lcm-logger file")->required();
  exp->add_option("--channel", exp_channel, "channel name")->required();
  exp->add_flag("--csv", exp_csv, "CSV (the only format)")->required();
  exp->add_option("--out", exp_out, "output file (default: stdout)");

  CLI::App* chan = app.add_subcommand("channels",
                                      "one line per channel: name type count first "
                                      "last (receive utimes)");
  std::string chan_log;
  chan->add_option("LOG", chan_log, "lcm-logger file")->required();

  return sg::run_program(app, argc, argv, [&]() -> int {
    if (*exp) return run_export(exp_log, exp_channel, exp_out);
    if (*chan) return run_channels(chan_log);
    if (log.empty()) throw std::runtime_error("no LOG given (see --help)");
    return run_report(log, out, no_plots, no_csv, horizons, quiet);
  });
}
