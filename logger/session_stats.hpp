#pragma once

/// The statistics of one recorded session, gathered in a single streaming pass with memory that
/// does not grow with the log: every distribution is a fixed log-spaced histogram, pending
/// predictions are a bounded queue, and the lists (occlusion episodes, grasp events) are capped.
///
///     sg::logger::SessionStats stats;                       // horizons 1, 4, 16
///     sg::logger::LogReader reader("session.lcmlog");
///     sg::logger::LogRecord event;
///     while (reader.next(event)) stats.add(event);
///     stats.finish(reader);
///     const sg::logger::SessionSummary& s = stats.summary();
///     std::printf("%s: %.1f Hz\n", s.channels[0].name.c_str(), s.channels[0].rate_hz);
///
/// Resolution: a percentile is the largest value seen in the histogram bin that holds it, at
/// most 12.2 % above the true one (20 bins a decade; the arm's interaction times use 200 a
/// decade, 1.2 %), and exact when the bin holds one distinct value (a constant latency, a
/// regular period). Means, RMS, minima and maxima are exact.
///
/// Phases: the prediction error is given for the whole session and per phase (the calibration,
/// the grasp machine idle, tracking, the approach, the carried ball: logger/session_phase.hpp),
/// each a fixed set of histograms; the phase changes are kept, the last 4096.
///
/// Which message is what: a message's type is its fingerprint (the first 8 bytes, big-endian,
/// compared with each type's getHash()); a channel's expected type is its name
/// (docs/architecture.md): a known fingerprint on the wrong channel is "wrong type", a known
/// fingerprint that does not decode to exactly the message's size is "wrong size", an unknown
/// fingerprint makes the channel "unknown" (LCM_SELF_TEST is listed apart as LCM's own). Only
/// messages on their own channel with their own type feed the session's figures; every message
/// counts in its channel's rate.

#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/process_watch.hpp"
#include "logger/log_reader.hpp"
#include "logger/plot_data.hpp"
#include "logger/session_phase.hpp"

namespace sg::logger {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Counts of positive values in log-spaced bins over [lo, hi), with exact count, mean, RMS,
/// minimum and maximum. Values below lo (zero and negatives included) go to an underflow bin,
/// values at or above hi to an overflow bin.
class LogHistogram {
 public:
  LogHistogram(double lo = 1e-2, double hi = 1e5, int bins_per_decade = 20);

  void add(double value);
  int64_t count() const { return count_; }
  double mean() const { return count_ ? sum_ / count_ : kNaN; }
  double rms() const { return count_ ? std::sqrt(sum_sq_ / count_) : kNaN; }
  double min() const { return count_ ? min_ : kNaN; }
  double max() const { return count_ ? max_ : kNaN; }
  /// The q-quantile (0..1): the largest value seen in the bin that holds it (never more than
  /// that bin's upper edge, exact when the bin holds one distinct value).
  double percentile(double q) const;
  /// Values whose bin lies entirely above `threshold` (bins straddling it count when their
  /// geometric centre is above it).
  int64_t count_above(double threshold) const;
  /// Width ratio of a bin, 10^(1 / bins_per_decade).
  double bin_ratio() const { return ratio_; }
  /// The occupied part of the histogram for plotting: log-spaced bins from the lowest to the
  /// highest occupied one, widened to span more than two decades (so that histogram_edges() of
  /// logger/session_plots.hpp takes them as log-spaced); under- and overflow join the end bins.
  Histogram to_plot() const;

 private:
  double edge(int bin) const;  // lower edge of bin (bin 0 is the underflow bin)
  double lo_, hi_, ratio_, log_lo_;
  int per_decade_;
  std::vector<int64_t> counts_;  // [underflow, bins..., overflow]
  std::vector<double> bin_max_;  // the largest value seen in each bin
  int64_t count_ = 0;
  double sum_ = 0, sum_sq_ = 0;
  double min_ = 0, max_ = 0;
};

/// Count, RMS, mean, p95 and maximum of a positive error, metres.
struct ErrorStats {
  LogHistogram hist{1e-6, 1e3, 20};
  void add(double e) { hist.add(e); }
};

/// A distribution as reported.
struct Quantiles {
  int64_t count = 0;
  double mean = kNaN, rms = kNaN, min = kNaN, p50 = kNaN, p95 = kNaN, p99 = kNaN, max = kNaN;
};
Quantiles quantiles(const LogHistogram& h);

/// One channel.
struct ChannelSummary {
  std::string name;
  std::string type;           ///< the type of its messages ("point3_t"), "?" when unknown
  std::string expected_type;  ///< what its name says, "" when the name is not a known channel
  int64_t count = 0;
  int64_t bytes = 0;
  int64_t first_recv_utime = 0, last_recv_utime = 0;
  double rate_hz = kNaN;          ///< (count - 1) / (last - first)
  double median_period_s = kNaN;  ///< of the receive-time gaps
  double largest_gap_s = kNaN;
  double largest_gap_at_s = kNaN;  ///< session time at the end of that gap
  int64_t gaps_over_3x = 0;        ///< gaps longer than 3 x the median period
  int64_t decoded = 0;             ///< messages decoded as the expected (or only) type
  int64_t wrong_size = 0;          ///< the right fingerprint, not exactly the right size
  int64_t wrong_type = 0;          ///< a known fingerprint other than the channel's type
  int64_t unknown_fingerprint = 0;
  std::string first_problem;  ///< the first wrong-size/-type message, described
};

/// One camera's blobs (BLOB_LEFT, BLOB_RIGHT).
struct CameraSummary {
  std::string channel;
  int64_t frames = 0, detected = 0;
  double detection_rate = kNaN;
  int64_t tracking_frames = 0, full_frame_frames = 0;
  double tracking_s = 0, full_frame_s = 0;  ///< capture-time spans attributed to each mode
};

/// Latency of one stage: receive time minus the message's utime or source_utime, milliseconds.
struct LatencySummary {
  std::string stage;      ///< the channel
  std::string reference;  ///< "utime" or "source_utime"
  int64_t negative = 0;   ///< received "before" it was made (clocks apart, or a replay)
  Quantiles ms;
};

/// Prediction error at one horizon, metres.
struct HorizonSummary {
  int h = 0;
  Quantiles vs_measurement;  ///< against OBJECT_POSITION, interpolated at the target time
  Quantiles vs_truth;        ///< against GROUND_TRUTH
  int64_t predictions = 0;
  int64_t unmatched_measurement = 0;  ///< no pair of measurements brackets the target time
  int64_t unmatched_truth = 0;
};

/// Prediction error at one horizon within one phase of the session, metres.
struct PhaseHorizon {
  int h = 0;
  Quantiles vs_measurement;  ///< against OBJECT_POSITION, interpolated at the target time
  Quantiles vs_truth;        ///< against GROUND_TRUTH
};

/// The predictions of one phase of the session (logger/session_phase.hpp). A prediction counts
/// in a phase when it was made in it (its OBJECT_TRAJECTORY received then) and its target time
/// lies in it too; "coasting" holds those made on fed-back samples through an occlusion (in a
/// phase where the ball follows its own path), "across phases" those whose target lies in
/// another phase than the one they were made in (or before the phase changes kept).
struct PhasePrediction {
  std::string phase;         ///< phase_name(), "coasting" or "across phases"
  std::string key;           ///< for report.json: phase_key(), "coasting" or "across_phases"
  double duration_s = kNaN;  ///< time spent in the phase (NaN for the last two)
  std::vector<PhaseHorizon> horizons;  ///< as StatsOptions::horizons
};

/// A run of OBJECT_POSITION with visible = false (or a gap in it longer than 0.5 s).
struct OcclusionEpisode {
  double start_s = 0;     ///< session time (capture time) of the first unseen frame
  double duration_s = 0;  ///< to the next visible frame
  bool gap = false;       ///< no messages at all rather than visible = false
  bool open_at_end = false;
  int64_t occluded_trajectories = 0;  ///< OBJECT_TRAJECTORY with STATUS_OCCLUDED inside it
  Quantiles vs_truth;                 ///< predictions whose target lies inside, against truth
  Quantiles after_vs_measurement;     ///< targets in the second after it, against measurements
};

struct OcclusionSummary {
  int64_t count = 0;
  double total_s = 0, longest_s = 0;
  std::vector<OcclusionEpisode> episodes;  ///< the first kMaxEpisodes
};

/// ARM_STATUS and ARM_COMMAND.
struct ArmSummary {
  int64_t statuses = 0, commands = 0;
  Quantiles interaction_s;  ///< one sample per change of interaction_time
  int64_t rejections = 0;   ///< changes of last_rejected_sequence
  int64_t errors = 0;       ///< entries into STATE_ERROR
  std::map<std::string, int64_t> command_modes;
};

/// One change of the grasp machine's state or outcome.
struct GraspEvent {
  double t_s = 0;  ///< session time of the message's utime
  int64_t utime = 0;
  std::string state, activity, action, outcome, message;
};

struct GraspSummary {
  int64_t statuses = 0;
  std::vector<GraspEvent> events;  ///< the first kMaxEvents
  int64_t event_count = 0;
  int64_t success = 0, failed = 0, aborted = 0;
  std::map<std::string, int64_t> commands;  ///< GRASP_COMMAND by command
};

struct TriangulationSummary {
  int64_t positions = 0, visible = 0;
  Quantiles residual_px;  ///< reprojection_error of visible positions
  int64_t behind_camera = 0, near_parallel = 0, large_residual = 0;
  /// m: each visible position's distance from the GROUND_TRUTH of the same capture time (the
  /// simulator's; count 0 without it). Only the last 512 of either wait for the other.
  Quantiles vs_truth_m;
};

/// A channel whose messages are of no stereograsp type.
struct UnknownChannel {
  std::string name;
  int64_t count = 0;
  std::string fingerprint;  ///< of the first message, hex ("" when shorter than 8 bytes)
};

/// One process that published PROCESS_STATUS in the session (issue 18).
struct ProcessSummary {
  std::string name;  ///< "process@host:pid"
  std::string host;
  double first_s = 0, last_s = 0;  ///< first and last heartbeat, s from the log's start
  std::string last_state;          ///< "ready", "stopping", ...
  int64_t bad = 0;                 ///< refused, undecodable and failed messages, as it counted
  std::string last_problem;
  std::string vouched_as;  ///< the identity it vouched as; "" when it ran without credentials
  int64_t unvouched = 0;   ///< messages it refused as not vouched for (docs/security.md)
  /// Those refusals, a line a (channel, claimed sender, verdict): "OBJECT_TRAJECTORY from
  /// 'sg-camera-sim': 300 not allowed".
  std::vector<std::string> refusals;
};

/// The processes and clocks of a session, from PROCESS_STATUS.
struct ProcessesSummary {
  std::vector<ProcessSummary> processes;
  /// "12.3 s: sg-vision@lab1:77 stopped beating (silent 2.5 s)": stops, silences, returns.
  std::vector<std::string> events;
  int64_t event_count = 0;
  std::string clock_reference;  ///< the host the offsets are to (sg-grasp's, else the first)
  std::vector<ProcessWatch::HostOffset> clocks;
  std::vector<std::string> clock_warnings;  ///< hosts off by more than the loop tolerates
};

/// Everything a report says.
struct SessionSummary {
  std::string path;
  int64_t file_size = 0, events = 0;
  int64_t first_utime = 0, last_utime = 0;  ///< receive times of the first and last event
  double duration_s = 0;
  std::vector<LogProblem> problems;
  int64_t problem_count = 0, skipped_bytes = 0;
  bool truncated = false;
  std::vector<ChannelSummary> channels;  ///< sorted by name
  std::vector<UnknownChannel> unknown;
  std::vector<UnknownChannel> lcm_internal;  ///< LCM_SELF_TEST
  int64_t wrong_size = 0, wrong_type = 0;
  std::vector<CameraSummary> cameras;
  TriangulationSummary triangulation;
  std::vector<LatencySummary> latency;
  std::vector<HorizonSummary> prediction;  ///< every prediction, whatever the phase
  /// Per phase: each Phase in order, then "coasting", then "across phases".
  std::vector<PhasePrediction> prediction_by_phase;
  OcclusionSummary occlusions;
  ArmSummary arm;
  GraspSummary grasp;
  ProcessesSummary processes;
};

/// Options of the pass.
struct StatsOptions {
  std::vector<int> horizons = {1, 4, 16};
  double max_bracket_s = 0.5;  ///< longest span between two measurements to interpolate in
  double occlusion_gap_s = 0.5;
};

/// The name of the stereograsp type whose fingerprint opens `data`, or "" when none does.
std::string type_of_message(const uint8_t* data, int size);
/// The type a channel carries by its name (docs/architecture.md), or "" for an unknown name.
std::string expected_type_of_channel(const std::string& channel);

/// Gathers a session's statistics event by event.
class SessionStats {
 public:
  static constexpr size_t kMaxEpisodes = 1000;
  static constexpr size_t kMaxEvents = 10000;

  explicit SessionStats(StatsOptions options = {});
  ~SessionStats();
  SessionStats(const SessionStats&) = delete;
  SessionStats& operator=(const SessionStats&) = delete;

  void add(const LogRecord& event) {
    add(event.channel, event.recv_utime, event.data, event.size, event.offset);
  }
  void add(const std::string& channel, int64_t recv_utime, const uint8_t* data, int size,
           int64_t offset = -1);

  /// Completes the figures; `reader` gives the file's own problems.
  void finish(const LogReader& reader);
  /// Completes the figures of events added by hand.
  void finish();

  const SessionSummary& summary() const { return summary_; }
  const PlotData& plot_data() const { return plots_; }

 private:
  struct Impl;
  // One event, after the clock and the phase have moved to its receive time.
  void add_event(const std::string& channel, int64_t recv, const uint8_t* data, int size,
                 int64_t offset);
  std::unique_ptr<Impl> impl_;
  SessionSummary summary_;
  PlotData plots_;
};

}  // namespace sg::logger
