#include "logger/session_stats.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <optional>

#include "common/grasp_names.hpp"
#include "common/message_types.hpp"
#include "common/safe_decode.hpp"

namespace sg::logger {
namespace {

/// A process's refusals of unvouched messages, a line a row of its PROCESS_STATUS.
std::vector<std::string> refusal_lines(const stereograsp::process_status_t& st) {
  std::vector<std::string> lines;
  const auto rows = std::min<size_t>({static_cast<size_t>(std::max(st.num_unvouched, 0)),
                                      st.unvouched_channel.size(), st.unvouched_sender.size(),
                                      st.unvouched_verdict.size(), st.unvouched_count.size()});
  for (size_t i = 0; i < rows; ++i) {
    const std::string from =
        st.unvouched_sender[i].empty() ? "" : " from '" + st.unvouched_sender[i] + "'";
    lines.push_back(st.unvouched_channel[i] + from + ": " + std::to_string(st.unvouched_count[i]) +
                    " " + (st.unvouched_verdict[i].empty() ? "refused" : st.unvouched_verdict[i]));
  }
  return lines;
}

using Vec3 = Eigen::Vector3d;

double seconds(int64_t us) { return static_cast<double>(us) * 1e-6; }

/// "12.3": seconds with one decimal.
std::string num(double v, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}

std::string hex64(uint64_t v) {
  char text[19];
  std::snprintf(text, sizeof(text), "0x%016llx", static_cast<unsigned long long>(v));
  return text;
}

uint64_t fingerprint(const uint8_t* data) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | data[i];
  return v;
}

struct TypeEntry {
  uint64_t hash;
  std::string name;
  int index;
};

const std::vector<TypeEntry>& type_table() {
  static const std::vector<TypeEntry> table = [] {
    std::vector<TypeEntry> t;
    int i = 0;
    for_each_message_type([&]<class T>() {
      t.push_back({static_cast<uint64_t>(T::getHash()), T::getTypeName(), i++});
    });
    return t;
  }();
  return table;
}

const TypeEntry* find_type(const uint8_t* data, int size) {
  if (size < 8) return nullptr;
  const uint64_t h = fingerprint(data);
  for (const TypeEntry& e : type_table())
    if (e.hash == h) return &e;
  return nullptr;
}

template <class T>
bool decode_exact(const uint8_t* data, int size, T& message) {
  return static_cast<bool>(safe_decode(data, size, message));
}

const char* command_name(int c) {
  static const char* names[] = {"?", "track", "grasp", "release", "abort", "home"};
  return c >= 1 && c <= 5 ? names[c] : "unknown";
}
const char* mode_name(int m) {
  static const char* names[] = {"?", "cartesian", "joints", "gripper only", "home"};
  return m >= 1 && m <= 4 ? names[m] : "other";
}

bool finite3(const Vec3& v) { return v.allFinite(); }

}  // namespace

// ---------------------------------------------------------------------------------------------
// LogHistogram

LogHistogram::LogHistogram(double lo, double hi, int bins_per_decade)
    : lo_(lo),
      hi_(hi),
      ratio_(std::pow(10.0, 1.0 / bins_per_decade)),
      log_lo_(std::log10(lo)),
      per_decade_(bins_per_decade) {
  const int bins = static_cast<int>(std::ceil(std::log10(hi / lo) * bins_per_decade - 1e-9));
  counts_.assign(static_cast<size_t>(bins) + 2, 0);
  bin_max_.assign(counts_.size(), -std::numeric_limits<double>::infinity());
}

double LogHistogram::edge(int bin) const {
  // bin 1 starts at lo; bin 0 is underflow
  return std::pow(10.0, log_lo_ + static_cast<double>(bin - 1) / per_decade_);
}

void LogHistogram::add(double value) {
  if (std::isnan(value)) return;
  size_t bin;
  if (!(value >= lo_)) {
    bin = 0;
  } else if (value >= hi_) {
    bin = counts_.size() - 1;
  } else {
    const double k = (std::log10(value) - log_lo_) * per_decade_;
    bin = std::min(static_cast<size_t>(k) + 1, counts_.size() - 2);
  }
  ++counts_[bin];
  bin_max_[bin] = std::max(bin_max_[bin], value);
  if (count_ == 0) min_ = max_ = value;
  min_ = std::min(min_, value);
  max_ = std::max(max_, value);
  ++count_;
  sum_ += value;
  sum_sq_ += value * value;
}

double LogHistogram::percentile(double q) const {
  if (count_ == 0) return kNaN;
  const double target = std::clamp(q, 0.0, 1.0) * static_cast<double>(count_);
  int64_t cumulative = 0;
  for (size_t b = 0; b < counts_.size(); ++b) {
    cumulative += counts_[b];
    if (counts_[b] > 0 && static_cast<double>(cumulative) >= target) return bin_max_[b];
  }
  return max_;
}

int64_t LogHistogram::count_above(double threshold) const {
  int64_t n = 0;
  for (size_t b = 0; b < counts_.size(); ++b) {
    if (counts_[b] == 0) continue;
    double centre;
    if (b == 0) {
      centre = lo_ * 0.5;
    } else if (b + 1 == counts_.size()) {
      centre = hi_;
    } else {
      centre = edge(static_cast<int>(b)) * std::sqrt(ratio_);
    }
    if (centre > threshold) n += counts_[b];
  }
  return n;
}

Histogram LogHistogram::to_plot() const {
  Histogram h;
  const int inner = static_cast<int>(counts_.size()) - 2;
  int first = -1, last = -1;
  for (int b = 0; b < inner; ++b) {
    const int64_t n = counts_[static_cast<size_t>(b) + 1] + (b == 0 ? counts_.front() : 0) +
                      (b == inner - 1 ? counts_.back() : 0);
    if (n == 0) continue;
    if (first < 0) first = b;
    last = b;
  }
  if (first < 0) {
    h.lo = lo_;
    h.hi = hi_;
    h.counts.assign(static_cast<size_t>(inner), 0);
    return h;
  }
  const int min_bins = 2 * per_decade_ + 2;  // more than two decades
  while (last - first + 1 < min_bins) {
    if (first > 0) --first;
    if (last - first + 1 < min_bins && last < inner - 1) ++last;
    if (first == 0 && last == inner - 1) break;
  }
  h.lo = edge(first + 1);
  h.hi = edge(last + 2);
  for (int b = first; b <= last; ++b)
    h.counts.push_back(counts_[static_cast<size_t>(b) + 1] + (b == 0 ? counts_.front() : 0) +
                       (b == inner - 1 ? counts_.back() : 0));
  return h;
}

Quantiles quantiles(const LogHistogram& h) {
  Quantiles q;
  q.count = h.count();
  if (q.count == 0) return q;
  q.mean = h.mean();
  q.rms = h.rms();
  q.min = h.min();
  q.max = h.max();
  q.p50 = h.percentile(0.5);
  q.p95 = h.percentile(0.95);
  q.p99 = h.percentile(0.99);
  return q;
}

std::string type_of_message(const uint8_t* data, int size) {
  const TypeEntry* e = find_type(data, size);
  return e ? e->name : "";
}

std::string expected_type_of_channel(const std::string& c) {
  if (c == "CAMERA_LEFT" || c == "CAMERA_RIGHT") return "image_t";
  if (c == "BLOB_LEFT" || c == "BLOB_RIGHT") return "blob_t";
  if (c == "OBJECT_POSITION" || c == "GROUND_TRUTH") return "point3_t";
  if (c == "OBJECT_TRAJECTORY") return "trajectory_t";
  if (c == "ARM_COMMAND") return "arm_cmd_t";
  if (c == "ARM_STATUS") return "arm_status_t";
  if (c == "GRASP_COMMAND") return "grasp_command_t";
  if (c == "GRASP_STATUS") return "grasp_status_t";
  if (c == "SIM_ARM_STATE") return "sim_arm_state_t";
  if (c == "PROCESS_STATUS") return "process_status_t";
  const std::string prefix = "BUS_CHECK_";
  if (c.rfind(prefix, 0) == 0) {
    std::string rest = c.substr(prefix.size());
    for (char& ch : rest) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    for (const TypeEntry& e : type_table())
      if (e.name == rest || e.name == rest + "_t") return e.name;
  }
  return "";
}

// ---------------------------------------------------------------------------------------------
// The pass

namespace {

struct ChannelState {
  ChannelSummary s;
  LogHistogram gaps{1e-5, 1e5, 20};  // seconds
  int64_t last_recv = 0;
  int64_t largest_gap = -1;
  int64_t largest_gap_end = 0;
};

struct CameraState {
  CameraSummary s;
  int64_t last_utime = 0;
  int last_mode = 0;
};

struct LatencyState {
  LatencySummary s;
  LogHistogram hist{1e-2, 1e5, 20};  // milliseconds
};

struct Sample {
  int64_t utime;
  Vec3 p;
};

/// A predicted point waiting for the reference samples around its target time.
struct Pending {
  int64_t target;
  Vec3 p;
  Phase made;           // the phase when its trajectory was received
  bool coasting;        // made on fed-back samples (an occlusion)
  int64_t target_recv;  // its target time on the log's clock
};

// The rows of the per-phase figures: each Phase, then these two.
constexpr int kCoastingRow = kPhaseCount, kAcrossRow = kPhaseCount + 1,
              kPhaseRows = kPhaseCount + 2;

/// A reference stream (measurements or truth) and the predictions waiting for it.
struct Reference {
  std::deque<Sample> recent;                      // the last few samples, oldest first
  std::vector<std::deque<Pending>> pending;       // per horizon, in target order
  std::vector<ErrorStats> error;                  // per horizon
  std::vector<std::vector<ErrorStats>> by_phase;  // per horizon, per row (kPhaseRows)
  std::vector<int64_t> unmatched;                 // per horizon
  static constexpr size_t kRecent = 16;
  static constexpr size_t kMaxPending = 4096;
};

struct EpisodeState {
  OcclusionEpisode e;
  int64_t start = 0, end = std::numeric_limits<int64_t>::max();
  ErrorStats vs_truth, after;
};

// Keeps the first problem of a channel, with where it was in the log.
void note_problem(ChannelSummary& s, const std::string& what, int64_t offset, int size) {
  if (!s.first_problem.empty()) return;
  s.first_problem = what + " (event at offset " + std::to_string(offset) + ", " +
                    std::to_string(size) + " bytes)";
}

}  // namespace

struct SessionStats::Impl {
  StatsOptions options;
  int64_t t0 = 0;
  bool started = false;
  int64_t first = 0, last = 0, events = 0;
  std::map<std::string, ChannelState> channels;
  ProcessWatch watch;  // PROCESS_STATUS, on the log's receive times
  ProcessesSummary processes;
  int64_t next_watch_check = 0;
  std::map<std::string, UnknownChannel> unknown, internal;
  std::map<std::string, CameraState> cameras;
  std::map<std::string, LatencyState> latency;
  TriangulationSummary triangulation;
  LogHistogram residual{1e-4, 1e4, 20};
  LogHistogram vs_truth{1e-6, 1e3, 20};
  std::deque<std::pair<int64_t, Vec3>> recent_truths, waiting_positions;  // by capture utime
  Reference measured, truth;
  std::vector<int64_t> predictions;   // per horizon
  std::deque<EpisodeState> episodes;  // stored ones (the first kMaxEpisodes)
  bool episode_open = false;
  int64_t episode_count = 0;
  double episode_total = 0, episode_longest = 0;
  int64_t last_position_utime = 0;
  bool have_position = false;
  // arm
  ArmSummary arm;
  LogHistogram interaction{1e-3, 1e3, 200};
  double last_interaction = kNaN;
  int64_t last_rejected = -1;
  bool have_arm = false;
  int last_arm_state = -1;
  // grasp
  GraspSummary grasp;
  bool have_grasp = false;
  int last_state = -100, last_outcome = -100;
  PlotData* plots = nullptr;
  // phases
  SessionPhase phases;
  bool held_open = false;  // a span of plots->ball_held is open

  double t(int64_t utime) const { return seconds(utime - t0); }

  /// Opens or closes a span of plots->ball_held as the arm takes or lets go of the ball (the
  /// first kMaxEvents spans).
  void follow_phase(int64_t recv) {
    if (!plots) return;
    const bool held = holds_the_ball(phases.current());
    if (held && !held_open && plots->ball_held.size() < SessionStats::kMaxEvents) {
      plots->ball_held.emplace_back(t(recv), t(recv));
      held_open = true;
    } else if (!held && held_open) {
      plots->ball_held.back().second = t(recv);
      held_open = false;
    }
  }

  /// The row a scored prediction goes to: its phase when made and at its target time alike.
  int phase_row(const Pending& pe) const {
    const std::optional<Phase> then = phases.at(pe.target_recv);
    if (!then || *then != pe.made) return kAcrossRow;
    if (pe.coasting && !holds_the_ball(pe.made)) return kCoastingRow;
    return static_cast<int>(pe.made);
  }

  void latency_of(const std::string& stage, const char* reference, int64_t recv, int64_t ref) {
    if (ref == 0) return;
    LatencyState& l = latency[stage];
    if (l.s.stage.empty()) {
      l.s.stage = stage;
      l.s.reference = reference;
    }
    const double ms = static_cast<double>(recv - ref) * 1e-3;
    if (ms < 0) ++l.s.negative;
    l.hist.add(ms);
  }

  EpisodeState* episode_containing(int64_t t_us) {
    for (auto it = episodes.rbegin(); it != episodes.rend() && it - episodes.rbegin() < 4; ++it)
      if (t_us >= it->start && t_us < it->end) return &*it;
    return nullptr;
  }
  EpisodeState* episode_before(int64_t t_us) {  // t in [end, end + 1 s)
    for (auto it = episodes.rbegin(); it != episodes.rend() && it - episodes.rbegin() < 4; ++it)
      if (it->end != std::numeric_limits<int64_t>::max() && t_us >= it->end &&
          t_us < it->end + 1'000'000)
        return &*it;
    return nullptr;
  }

  void record(Reference& ref, bool is_truth, size_t hi, const Pending& pe, const Vec3& actual) {
    const double e = (pe.p - actual).norm();
    ref.error[hi].add(e);
    ref.by_phase[hi][static_cast<size_t>(phase_row(pe))].add(e);
    if (is_truth) {
      if (EpisodeState* ep = episode_containing(pe.target)) ep->vs_truth.add(e);
    } else {
      if (EpisodeState* ep = episode_before(pe.target)) ep->after.add(e);
    }
  }

  /// The reference position at `target` from the two recent samples that bracket it.
  std::optional<Vec3> bracket(const Reference& ref, int64_t target) const {
    const int64_t max_span = static_cast<int64_t>(options.max_bracket_s * 1e6);
    for (size_t i = 1; i < ref.recent.size(); ++i) {
      const Sample& a = ref.recent[i - 1];
      const Sample& b = ref.recent[i];
      if (target >= a.utime && target <= b.utime) {
        if (b.utime - a.utime > max_span) return std::nullopt;
        if (b.utime == a.utime) return b.p;
        const double f = static_cast<double>(target - a.utime) / (b.utime - a.utime);
        return Vec3(a.p + f * (b.p - a.p));
      }
    }
    return std::nullopt;
  }

  void add_reference_sample(Reference& ref, bool is_truth, int64_t utime, const Vec3& p) {
    if (!ref.recent.empty() && utime <= ref.recent.back().utime) return;  // out of order
    ref.recent.push_back({utime, p});
    if (ref.recent.size() > Reference::kRecent) ref.recent.pop_front();
    for (size_t hi = 0; hi < ref.pending.size(); ++hi) {
      auto& q = ref.pending[hi];
      while (!q.empty() && q.front().target <= utime) {
        const Pending& pe = q.front();
        if (auto actual = bracket(ref, pe.target)) {
          record(ref, is_truth, hi, pe, *actual);
        } else {
          ++ref.unmatched[hi];
        }
        q.pop_front();
      }
    }
  }

  void add_prediction(Reference& ref, bool is_truth, size_t hi, const Pending& pe, int64_t recv) {
    const int64_t target = pe.target;
    auto& q = ref.pending[hi];
    // Drop what can no longer be matched: its reference would have been logged long ago.
    while (!q.empty() &&
           (q.front().target < recv - 10'000'000 || q.size() >= Reference::kMaxPending)) {
      ++ref.unmatched[hi];
      q.pop_front();
    }
    if (!ref.recent.empty() && target <= ref.recent.back().utime) {
      if (auto actual = bracket(ref, target)) {
        record(ref, is_truth, hi, pe, *actual);
      } else {
        ++ref.unmatched[hi];
      }
      return;
    }
    if (!q.empty() && target < q.back().target) {  // a restarted predictor: keep the order
      q.clear();
    }
    q.push_back(pe);
  }

  void open_episode(int64_t start, bool gap) {
    ++episode_count;
    episode_open = true;
    if (episodes.size() >= kMaxEpisodes) {
      return;  // counted, not stored
    }
    EpisodeState ep;
    ep.start = start;
    ep.e.start_s = t(start);
    ep.e.gap = gap;
    episodes.push_back(std::move(ep));
  }
  void close_episode(int64_t end, bool at_end) {
    if (!episode_open) return;
    episode_open = false;
    if (episodes.empty()) return;
    EpisodeState& ep = episodes.back();
    if (ep.end != std::numeric_limits<int64_t>::max()) return;  // not stored (over the cap)
    ep.end = end;
    ep.e.open_at_end = at_end;
    ep.e.duration_s = seconds(end - ep.start);
    episode_total += ep.e.duration_s;
    episode_longest = std::max(episode_longest, ep.e.duration_s);
    if (plots) plots->occlusions.emplace_back(ep.e.start_s, t(end));
  }

  // --- per type -------------------------------------------------------------------------------

  void on_blob(const std::string& channel, int64_t recv, const stereograsp::blob_t& b) {
    latency_of(channel, "utime", recv, b.utime);
    CameraState& c = cameras[channel];
    c.s.channel = channel;
    ++c.s.frames;
    if (b.found) ++c.s.detected;
    if (b.mode == stereograsp::blob_t::MODE_TRACKING) ++c.s.tracking_frames;
    if (b.mode == stereograsp::blob_t::MODE_FULL_FRAME) ++c.s.full_frame_frames;
    if (c.last_utime != 0 && b.utime > c.last_utime) {
      const double dt = std::min(seconds(b.utime - c.last_utime), 1.0);
      if (c.last_mode == stereograsp::blob_t::MODE_TRACKING) c.s.tracking_s += dt;
      if (c.last_mode == stereograsp::blob_t::MODE_FULL_FRAME) c.s.full_frame_s += dt;
    }
    c.last_utime = b.utime;
    c.last_mode = b.mode;
  }

  void on_position(int64_t recv, const stereograsp::point3_t& p) {
    latency_of("OBJECT_POSITION", "utime", recv, p.utime);
    ++triangulation.positions;
    const Vec3 x(p.position[0], p.position[1], p.position[2]);
    const bool visible = p.visible && finite3(x);
    if (visible) {
      ++triangulation.visible;
      residual.add(p.reprojection_error);
      if (p.flags & stereograsp::point3_t::FLAG_BEHIND_CAMERA) ++triangulation.behind_camera;
      if (p.flags & stereograsp::point3_t::FLAG_NEAR_PARALLEL_RAYS) ++triangulation.near_parallel;
      if (p.flags & stereograsp::point3_t::FLAG_LARGE_RESIDUAL) ++triangulation.large_residual;
      if (plots) plots->measured.add(t(p.utime), x);
      match_truth(waiting_positions, recent_truths, p.utime, x);
    }
    const int64_t gap_us = static_cast<int64_t>(options.occlusion_gap_s * 1e6);
    if (visible) {
      if (episode_open) {
        close_episode(p.utime, false);
      } else if (have_position && p.utime - last_position_utime > gap_us) {
        open_episode(last_position_utime, true);
        close_episode(p.utime, false);
      }
      add_reference_sample(measured, false, p.utime, x);
    } else if (!episode_open) {
      open_episode(p.utime, false);
    }
    have_position = true;
    last_position_utime = p.utime;
  }

  void on_truth(int64_t recv, const stereograsp::point3_t& p) {
    latency_of("GROUND_TRUTH", "utime", recv, p.utime);
    const Vec3 x(p.position[0], p.position[1], p.position[2]);
    if (!finite3(x)) return;
    if (plots) plots->truth.add(t(p.utime), x);
    add_reference_sample(truth, true, p.utime, x);
    match_truth(recent_truths, waiting_positions, p.utime, x);
  }

  /// Adds |x - y| to vs_truth for the sample y of `others` taken at `utime`, or keeps x in
  /// `mine` for one that comes later (the last 512: a log of any size stays in bounded memory).
  void match_truth(std::deque<std::pair<int64_t, Vec3>>& mine,
                   std::deque<std::pair<int64_t, Vec3>>& others, int64_t utime, const Vec3& x) {
    const auto it = std::find_if(others.rbegin(), others.rend(),
                                 [&](const auto& o) { return o.first == utime; });
    if (it != others.rend()) {
      vs_truth.add((it->second - x).norm());
      others.erase(std::next(it).base());
      return;
    }
    mine.emplace_back(utime, x);
    if (mine.size() > 512) mine.pop_front();
  }

  void on_trajectory(int64_t recv, const stereograsp::trajectory_t& m) {
    latency_of("OBJECT_TRAJECTORY", "source_utime", recv, m.source_utime);
    if (m.status == stereograsp::trajectory_t::STATUS_OCCLUDED && episode_open &&
        !episodes.empty() && episodes.back().end == std::numeric_limits<int64_t>::max())
      ++episodes.back().e.occluded_trajectories;
    const int n = std::min<int>(m.num_points, static_cast<int>(m.position.size()));
    // The log's clock at a target: the trajectory's receive time plus how far ahead it looks.
    const int64_t made_utime = m.source_utime != 0 ? m.source_utime : m.utime;
    const bool coasting =
        m.occluded_samples > 0 || m.status == stereograsp::trajectory_t::STATUS_OCCLUDED;
    for (size_t hi = 0; hi < options.horizons.size(); ++hi) {
      const int h = options.horizons[hi];
      if (h < 1 || h > n || m.position[h - 1].size() != 3) continue;
      const Vec3 p(m.position[h - 1][0], m.position[h - 1][1], m.position[h - 1][2]);
      if (!finite3(p)) continue;
      const int64_t target = m.start_utime + static_cast<int64_t>(h - 1) * m.period_us;
      const Pending pe{target, p, phases.current(), coasting, recv + (target - made_utime)};
      ++predictions[hi];
      add_prediction(measured, false, hi, pe, recv);
      add_prediction(truth, true, hi, pe, recv);
    }
    if (plots) {
      const int h = plots->predicted_horizon;
      if (h >= 1 && h <= n && m.position[h - 1].size() == 3) {
        const Vec3 p(m.position[h - 1][0], m.position[h - 1][1], m.position[h - 1][2]);
        if (finite3(p))
          plots->predicted.add(t(m.start_utime + static_cast<int64_t>(h - 1) * m.period_us), p);
      }
    }
  }

  void on_arm_command(int64_t recv, const stereograsp::arm_cmd_t& c) {
    latency_of("ARM_COMMAND", "source_utime", recv, c.source_utime);
    phases.on_arm_command(recv);
    ++arm.commands;
    ++arm.command_modes[mode_name(c.mode)];
    if (c.mode == stereograsp::arm_cmd_t::MODE_CARTESIAN && plots) {
      const Vec3 p(c.position[0], c.position[1], c.position[2]);
      if (finite3(p)) plots->arm_target.add(t(c.utime), p);
    }
  }

  void on_arm_status(int64_t recv, const stereograsp::arm_status_t& s) {
    latency_of("ARM_STATUS", "utime", recv, s.utime);
    ++arm.statuses;
    if (std::isfinite(s.interaction_time) && s.interaction_time > 0 &&
        s.interaction_time != last_interaction)
      interaction.add(s.interaction_time);
    last_interaction = s.interaction_time;
    if (have_arm && s.last_rejected_sequence != last_rejected && s.last_rejected_sequence >= 0)
      ++arm.rejections;
    if (!have_arm && s.last_rejected_sequence >= 0) ++arm.rejections;
    last_rejected = s.last_rejected_sequence;
    if (s.state == stereograsp::arm_status_t::STATE_ERROR && last_arm_state != s.state)
      ++arm.errors;
    last_arm_state = s.state;
    have_arm = true;
    // A driver that has not reached its controller yet knows no joints: no tool position.
    const Vec3 p(s.tool_position[0], s.tool_position[1], s.tool_position[2]);
    const bool known = s.state != stereograsp::arm_status_t::STATE_DISCONNECTED;
    if (plots && known && finite3(p)) plots->arm_actual.add(t(s.utime), p);
  }

  void on_grasp_status(int64_t recv, const stereograsp::grasp_status_t& g) {
    latency_of("GRASP_STATUS", "source_utime", recv, g.source_utime);
    ++grasp.statuses;
    phases.on_grasp_status(recv, g.state, g.activity);
    const bool state_changed = g.state != last_state;
    const bool outcome_changed = g.outcome != last_outcome;
    if (outcome_changed && have_grasp) {
      if (g.outcome == stereograsp::grasp_status_t::OUTCOME_SUCCESS) ++grasp.success;
      if (g.outcome == stereograsp::grasp_status_t::OUTCOME_FAILED) ++grasp.failed;
      if (g.outcome == stereograsp::grasp_status_t::OUTCOME_ABORTED) ++grasp.aborted;
    }
    if (state_changed || outcome_changed) {
      ++grasp.event_count;
      GraspEvent e;
      e.t_s = t(g.utime);
      e.utime = g.utime;
      e.state = grasp_state_name(g.state);
      e.activity = grasp_activity_name(g.activity);
      e.action = grasp_action_name(g.last_action);
      e.outcome = grasp_outcome_name(g.outcome);
      e.message = g.message;
      if (plots && plots->events.size() < kMaxEvents) {
        std::string label = e.state;
        if (outcome_changed && g.outcome != 0) label += std::string(" (") + e.outcome + ")";
        plots->events.emplace_back(e.t_s, label);
      }
      if (grasp.events.size() < kMaxEvents) grasp.events.push_back(std::move(e));
    }
    last_state = g.state;
    last_outcome = g.outcome;
    have_grasp = true;
  }

  // One decoded message of each kind, to what it feeds (kinds without figures: nothing).
  void on_message(const std::string& channel, int64_t recv, const stereograsp::image_t& msg) {
    latency_of(channel, "utime", recv, msg.utime);
  }
  void on_message(const std::string& channel, int64_t recv, const stereograsp::blob_t& msg) {
    on_blob(channel, recv, msg);
  }
  void on_message(const std::string& channel, int64_t recv, const stereograsp::point3_t& msg) {
    if (channel == "OBJECT_POSITION") on_position(recv, msg);
    if (channel == "GROUND_TRUTH") on_truth(recv, msg);
  }
  void on_message(const std::string&, int64_t recv, const stereograsp::trajectory_t& msg) {
    on_trajectory(recv, msg);
  }
  void on_message(const std::string&, int64_t recv, const stereograsp::arm_cmd_t& msg) {
    on_arm_command(recv, msg);
  }
  void on_message(const std::string&, int64_t recv, const stereograsp::arm_status_t& msg) {
    on_arm_status(recv, msg);
  }
  void on_message(const std::string& channel, int64_t recv,
                  const stereograsp::grasp_command_t& msg) {
    latency_of(channel, "utime", recv, msg.utime);
    ++grasp.commands[command_name(msg.command)];
  }
  void on_message(const std::string&, int64_t recv, const stereograsp::grasp_status_t& msg) {
    on_grasp_status(recv, msg);
  }
  void on_message(const std::string& channel, int64_t recv,
                  const stereograsp::sim_arm_state_t& msg) {
    latency_of(channel, "utime", recv, msg.utime);
    if (channel == "SIM_ARM_STATE") phases.on_sim_arm_state(recv, msg.holding_object);
  }
  void on_message(const std::string&, int64_t recv, const stereograsp::process_status_t& msg) {
    watch.receive(msg, recv);
  }
  template <class T>
  void on_message(const std::string&, int64_t, const T&) {}

  // The processes' stops, silences and returns up to `recv`, checked twice a second of the log.
  void check_processes(int64_t recv, bool final = false) {
    if (!final && recv < next_watch_check) return;
    next_watch_check = recv + 500'000;
    for (const ProcessWatch::Event& e : watch.check(recv)) {
      if (e.kind == ProcessWatch::Event::kJoined) continue;
      if (processes.events.size() < kMaxEvents)
        processes.events.push_back(num(t(e.utime), 1) + " s: " + e.line);
      ++processes.event_count;
    }
  }

  // The process table and the clocks, at the end of the log.
  void summarize_processes(ProcessesSummary& s) {
    check_processes(last, true);
    s = processes;
    s.processes.clear();
    for (const ProcessWatch::Process& p : watch.processes()) {
      const auto& st = p.last;
      s.processes.push_back(
          {p.name, st.host, t(p.first_heard), t(p.last_heard), state_name(st.state),
           st.decode_errors + st.refused_inputs + st.handler_errors, st.last_problem, st.vouched_as,
           st.unvouched_inputs, refusal_lines(st)});
    }
    const ProcessWatch::Process* grasp_process = watch.find("sg-grasp");
    const auto hosts = watch.hosts();
    s.clock_reference = grasp_process ? grasp_process->last.host : hosts.empty() ? "" : hosts[0];
    s.clocks = watch.host_offsets(s.clock_reference);
    s.clock_warnings = clock_warnings(s.clocks, s.clock_reference);
  }

  // The session's span and event count; its first event sets t0.
  void count_event(int64_t recv) {
    if (!started) {
      started = true;
      t0 = recv;
      first = recv;
    }
    last = std::max(last, recv);
    ++events;
  }

  // One more event on `channel`: its count, bytes, and the gap since its previous event.
  ChannelState& count_arrival(const std::string& channel, int64_t recv, int size) {
    ChannelState& cs = channels[channel];
    ChannelSummary& s = cs.s;
    if (s.count == 0) {
      s.name = channel;
      s.expected_type = expected_type_of_channel(channel);
      s.first_recv_utime = recv;
    } else {
      const int64_t gap = recv - cs.last_recv;
      cs.gaps.add(seconds(gap));
      if (gap > cs.largest_gap) {
        cs.largest_gap = gap;
        cs.largest_gap_end = recv;
      }
    }
    ++s.count;
    s.bytes += size;
    s.last_recv_utime = recv;
    cs.last_recv = recv;
    return cs;
  }

  // A fingerprint of no known type: an unknown channel is listed, a known one has a problem.
  void on_unknown_type(const std::string& channel, ChannelState& cs, const uint8_t* data, int size,
                       int64_t offset) {
    ChannelSummary& s = cs.s;
    ++s.unknown_fingerprint;
    if (s.type.empty()) s.type = "?";
    if (!s.expected_type.empty()) {
      note_problem(s, "unknown fingerprint", offset, size);
      return;
    }
    UnknownChannel& u = unknown[channel];
    if (u.count == 0) {
      u.name = channel;
      if (size >= 8) u.fingerprint = hex64(fingerprint(data));
    }
    ++u.count;
  }

  // Decodes `data` exactly as the type at `type_index` of MessageTypes and, when `feed`, passes
  // it on; false when it does not decode exactly.
  bool decode_and_feed(const std::string& channel, int64_t recv, int type_index,
                       const uint8_t* data, int size, bool feed) {
    bool ok = false;
    int index = 0;
    for_each_message_type([&]<class T>() {
      if (index++ != type_index) return;
      T msg{};
      ok = decode_exact(data, size, msg);
      if (ok && feed) on_message(channel, recv, msg);
    });
    return ok;
  }

  // Per channel: rate, median period, the largest gap and gaps over 3x the median; the unknown
  // and LCM's own channels; the problem totals.
  void summarize_channels(SessionSummary& s) const {
    s.channels.clear();
    s.wrong_size = s.wrong_type = 0;
    for (const auto& [name, cs] : channels) {
      ChannelSummary c = cs.s;
      if (c.count >= 2 && c.last_recv_utime > c.first_recv_utime)
        c.rate_hz =
            static_cast<double>(c.count - 1) / seconds(c.last_recv_utime - c.first_recv_utime);
      if (cs.gaps.count() > 0) {
        c.median_period_s = cs.gaps.percentile(0.5);
        c.largest_gap_s = seconds(cs.largest_gap);
        c.largest_gap_at_s = t(cs.largest_gap_end);
        c.gaps_over_3x = cs.gaps.count_above(3 * c.median_period_s);
      }
      if (c.type.empty()) c.type = "?";
      s.wrong_size += c.wrong_size;
      s.wrong_type += c.wrong_type;
      s.channels.push_back(std::move(c));
    }
    s.unknown.clear();
    for (const auto& [name, u] : unknown) s.unknown.push_back(u);
    s.lcm_internal.clear();
    for (const auto& [name, u] : internal) s.lcm_internal.push_back(u);
  }

  // Per horizon: the errors against measurements and truth, and predictions never matched.
  void summarize_prediction(SessionSummary& s) const {
    s.prediction.clear();
    for (size_t hi = 0; hi < options.horizons.size(); ++hi) {
      HorizonSummary h;
      h.h = options.horizons[hi];
      h.predictions = predictions[hi];
      h.vs_measurement = quantiles(measured.error[hi].hist);
      h.vs_truth = quantiles(truth.error[hi].hist);
      h.unmatched_measurement =
          measured.unmatched[hi] + static_cast<int64_t>(measured.pending[hi].size());
      h.unmatched_truth = truth.unmatched[hi] + static_cast<int64_t>(truth.pending[hi].size());
      s.prediction.push_back(h);
    }
    summarize_phases(s);
  }

  // Per phase (then coasting, then across phases), per horizon: the errors scored there.
  void summarize_phases(SessionSummary& s) const {
    s.prediction_by_phase.clear();
    for (int row = 0; row < kPhaseRows; ++row) {
      PhasePrediction p;
      if (row < kPhaseCount) {
        const Phase phase = static_cast<Phase>(row);
        p.phase = phase_name(phase);
        p.key = phase_key(phase);
        p.duration_s = phases.seconds_in(phase);
      } else {
        p.phase = row == kCoastingRow ? "coasting" : "across phases";
        p.key = row == kCoastingRow ? "coasting" : "across_phases";
      }
      for (size_t hi = 0; hi < options.horizons.size(); ++hi) {
        const size_t r = static_cast<size_t>(row);
        p.horizons.push_back({options.horizons[hi], quantiles(measured.by_phase[hi][r].hist),
                              quantiles(truth.by_phase[hi][r].hist)});
      }
      s.prediction_by_phase.push_back(std::move(p));
    }
  }

  // Occlusion episodes; one still open at the end closes at the last position.
  void summarize_occlusions(SessionSummary& s) {
    if (episode_open) close_episode(last_position_utime, true);
    s.occlusions.count = episode_count;
    s.occlusions.total_s = episode_total;
    s.occlusions.longest_s = episode_longest;
    s.occlusions.episodes.clear();
    for (const EpisodeState& ep : episodes) {
      OcclusionEpisode e = ep.e;
      e.vs_truth = quantiles(ep.vs_truth.hist);
      e.after_vs_measurement = quantiles(ep.after.hist);
      s.occlusions.episodes.push_back(e);
    }
  }
};

SessionStats::SessionStats(StatsOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  const size_t n = impl_->options.horizons.size();
  for (Reference* r : {&impl_->measured, &impl_->truth}) {
    r->pending.resize(n);
    r->error.resize(n);
    r->by_phase.assign(n, std::vector<ErrorStats>(kPhaseRows));
    r->unmatched.assign(n, 0);
  }
  impl_->predictions.assign(n, 0);
  impl_->plots = &plots_;
  plots_.predicted_horizon =
      std::find(impl_->options.horizons.begin(), impl_->options.horizons.end(), 4) !=
                  impl_->options.horizons.end() ||
              impl_->options.horizons.empty()
          ? 4
          : impl_->options.horizons.front();
}

SessionStats::~SessionStats() = default;

void SessionStats::add(const std::string& channel, int64_t recv, const uint8_t* data, int size,
                       int64_t offset) {
  Impl& m = *impl_;
  m.count_event(recv);
  m.phases.advance(recv);
  m.check_processes(recv);
  add_event(channel, recv, data, size, offset);
  m.follow_phase(recv);
}

void SessionStats::add_event(const std::string& channel, int64_t recv, const uint8_t* data,
                             int size, int64_t offset) {
  Impl& m = *impl_;
  if (channel == "LCM_SELF_TEST") {
    UnknownChannel& u = m.internal[channel];
    u.name = channel;
    ++u.count;
    return;
  }
  ChannelState& cs = m.count_arrival(channel, recv, size);
  ChannelSummary& s = cs.s;
  const TypeEntry* type = find_type(data, size);
  if (type == nullptr) {
    m.on_unknown_type(channel, cs, data, size, offset);
    return;
  }
  if (s.type.empty() || s.type == "?") s.type = type->name;
  if (!s.expected_type.empty() && type->name != s.expected_type) {
    ++s.wrong_type;
    note_problem(s, "a " + type->name + " where " + s.expected_type + " belongs", offset, size);
    return;
  }
  // Decode exactly, then feed the figures when the channel is one of the session's own.
  const bool session_channel = !s.expected_type.empty() && channel.rfind("BUS_CHECK_", 0) != 0;
  if (m.decode_and_feed(channel, recv, type->index, data, size, session_channel)) {
    ++s.decoded;
  } else {
    ++s.wrong_size;
    note_problem(s, "wrong size for " + type->name, offset, size);
  }
}

void SessionStats::finish(const LogReader& reader) {
  finish();
  summary_.file_size = reader.file_size();
  summary_.problems = reader.problems();
  summary_.problem_count = reader.problem_count();
  summary_.skipped_bytes = reader.skipped_bytes();
  summary_.truncated = reader.truncated();
}

void SessionStats::finish() {
  Impl& m = *impl_;
  SessionSummary& s = summary_;
  s.events = m.events;
  s.first_utime = m.first;
  s.last_utime = m.last;
  s.duration_s = m.started ? seconds(m.last - m.first) : 0;
  m.summarize_channels(s);
  s.cameras.clear();
  for (auto& [name, c] : m.cameras) {
    CameraSummary cam = c.s;
    if (cam.frames > 0) cam.detection_rate = static_cast<double>(cam.detected) / cam.frames;
    s.cameras.push_back(cam);
  }
  s.triangulation = m.triangulation;
  s.triangulation.residual_px = quantiles(m.residual);
  s.triangulation.vs_truth_m = quantiles(m.vs_truth);
  s.latency.clear();
  plots_.latency_ms.clear();
  for (auto& [name, l] : m.latency) {
    LatencySummary ls = l.s;
    ls.ms = quantiles(l.hist);
    s.latency.push_back(ls);
    plots_.latency_ms[name] = l.hist.to_plot();
  }
  m.summarize_prediction(s);
  m.summarize_occlusions(s);
  if (m.held_open) plots_.ball_held.back().second = m.t(m.last);
  s.arm = m.arm;
  s.arm.interaction_s = quantiles(m.interaction);
  s.grasp = m.grasp;
  m.summarize_processes(s.processes);
}

}  // namespace sg::logger
