// sg-bus-check: is the LCM bus between these processes (or these lab machines) sound?
//
//   machine A:  sg-bus-check receive --count 1000 --lcm-url 'udpm://239.255.76.67:7667?ttl=1'
//   machine B:  sg-bus-check send    --count 1000 --lcm-url 'udpm://239.255.76.67:7667?ttl=1'
//
// `send` publishes one message of every stereograsp type in turn on BUS_CHECK_<TYPE>, each with
// contents derived from its utime; `receive` checks every byte and reports loss, corruption and
// latency; `verify-log` checks a log that lcm-logger recorded of such a stream.
//
//   sg-bus-check hostile --rate 2000 --random-bodies 1000 --seed 1   # issue 15's hostile bus
//
// `hostile` publishes, on every channel the system reads, packets that are almost messages of
// the channel's type: each 4-byte window of a typical message set to 0, -1, 2^31-1 and 10^9,
// random bodies behind the type's fingerprint, every truncation, and the other types' messages
// (common/bus_check.hpp). Every process must survive it, within its memory, and the arm must not
// move (scripts/hostile_bus.sh, docs/reliability.md).
//
//   sg-bus-check health [--duration 3] [--watch]                    # issue 18: who is there
//
// `health` listens to PROCESS_STATUS, takes part in the clock exchange, and prints every process
// with its host, state, uptime, rates and bad messages, every host's clock offset to this one,
// and a warning for each host whose clock is off by more than the loop tolerates (exit 1 then).
// With --watch it runs until interrupted and prints, as they happen, the processes that join,
// stop beating (2.5 s silent), come back or stop, and the clock warnings.

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "common/bus.hpp"
#include "common/bus_check.hpp"
#include "common/clock.hpp"
#include "common/process_watch.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "logger/log_reader.hpp"

namespace {

using namespace std::chrono;

struct SendOptions {
  int64_t count = 1000;
  double rate_hz = 100.0;
  double duration_s = 0.0;
};

struct ReceiveOptions {
  int64_t count = 0;
  double timeout_s = 30.0;
};

/// Tallies checked messages: per channel, corrupt, duplicates, latency.
class Tally {
 public:
  void add(const std::string& channel_name, const uint8_t* data, int size, int64_t recv_utime) {
    const auto verdict = sg::bus_check::verify(channel_name, data, size);
    if (!verdict) {
      ++other_[channel_name];  // e.g. LCM_SELF_TEST, which LCM's udpm sends when a bus opens
      return;
    }
    ++per_channel_[channel_name];
    if (!verdict->intact) {
      ++corrupt_;
      spdlog::warn("{}: a {}-byte message differs from what was sent", channel_name, size);
      return;
    }
    if (!seen_.insert(verdict->utime).second) ++duplicates_;
    if (recv_utime > 0) latencies_us_.push_back(recv_utime - verdict->utime);
  }

  int64_t intact() const { return static_cast<int64_t>(seen_.size()); }
  int64_t corrupt() const { return corrupt_; }
  int64_t duplicates() const { return duplicates_; }

  /// One summary line; `expected` 0 means no expectation; `seconds` < 0 for a log.
  std::string summary(int64_t expected, double seconds) const {
    std::string line = (seconds < 0 ? "intact " : "received ") + std::to_string(intact());
    if (expected > 0) {
      line += " of " + std::to_string(expected) + " (" +
              std::to_string(std::max<int64_t>(0, expected - intact())) + " lost)";
    }
    char tail[256];
    std::snprintf(tail, sizeof tail, " on %zu channels", per_channel_.size());
    line += tail;
    if (seconds >= 0) {
      std::snprintf(tail, sizeof tail, " in %.2f s", seconds);
      line += tail;
    }
    std::snprintf(tail, sizeof tail, "; %lld corrupt, %lld duplicate",
                  static_cast<long long>(corrupt_), static_cast<long long>(duplicates_));
    line += tail;
    for (const auto& [name, n] : other_) line += ", " + std::to_string(n) + " on " + name;
    if (!latencies_us_.empty()) {
      std::vector<int64_t> sorted = latencies_us_;
      std::sort(sorted.begin(), sorted.end());
      auto at = [&](double q) {
        return sorted[static_cast<size_t>(q * static_cast<double>(sorted.size() - 1))] / 1000.0;
      };
      std::snprintf(tail, sizeof tail, "; latency p50 %.3f ms, p99 %.3f ms, max %.3f ms", at(0.5),
                    at(0.99), sorted.back() / 1000.0);
      line += tail;
    }
    return line;
  }

  std::string per_channel() const {
    std::string text;
    for (const auto& [name, n] : per_channel_)
      text += "  " + name + ": " + std::to_string(n) + "\n";
    return text;
  }

 private:
  std::map<std::string, int64_t> per_channel_;
  std::set<int64_t> seen_;
  std::vector<int64_t> latencies_us_;
  int64_t corrupt_ = 0;
  int64_t duplicates_ = 0;
  std::map<std::string, int64_t> other_;
};

int run_send(sg::Bus& bus, const SendOptions& options) {
  const auto start = steady_clock::now();
  const auto period = duration<double>(1.0 / options.rate_hz);
  int64_t last_utime = 0;
  int64_t sent = 0;
  for (; options.count == 0 || sent < options.count; ++sent) {
    if (sg::shutdown_requested()) break;
    if (options.duration_s > 0 &&
        steady_clock::now() - start >= duration<double>(options.duration_s))
      break;
    const int type_index = static_cast<int>(sent % sg::bus_check::type_count());
    last_utime = std::max(sg::now_utime(), last_utime + 1);  // unique, increasing
    const std::vector<uint8_t> bytes = sg::bus_check::encode(type_index, last_utime);
    bus.publish_raw(sg::bus_check::channel(type_index), bytes.data(),
                    static_cast<int>(bytes.size()));
    std::this_thread::sleep_until(start +
                                  duration_cast<steady_clock::duration>(period * (sent + 1)));
  }
  const double seconds = duration<double>(steady_clock::now() - start).count();
  std::printf("sent %lld messages of %d types in %.2f s (%lld publish errors)\n",
              static_cast<long long>(sent), sg::bus_check::type_count(), seconds,
              static_cast<long long>(bus.publish_errors()));
  return bus.publish_errors() == 0 ? 0 : 1;
}

int run_receive(sg::Bus& bus, const ReceiveOptions& options) {
  Tally tally;
  bus.subscribe_raw(std::string(sg::bus_check::kChannelPrefix) + ".*",
                    [&](const sg::RawMessage& raw) {
                      tally.add(raw.info.channel, raw.data, raw.info.size, raw.info.recv_utime);
                    });
  const auto start = steady_clock::now();
  auto last_arrival = start;
  int64_t handled = 0;
  bus.spin([&] {
    if (tally.intact() + tally.corrupt() > handled) {
      handled = tally.intact() + tally.corrupt();
      last_arrival = steady_clock::now();
    }
    if (options.count > 0 && tally.intact() >= options.count) return false;
    // Time out only on silence, so a long stream is not cut short.
    return options.timeout_s <= 0 ||
           steady_clock::now() - last_arrival < duration<double>(options.timeout_s);
  });
  const double seconds = duration<double>(steady_clock::now() - start).count();
  std::printf("%s\n", tally.summary(options.count, seconds).c_str());
  const bool complete = options.count == 0 || tally.intact() >= options.count;
  return complete && tally.corrupt() == 0 && tally.duplicates() == 0 ? 0 : 1;
}

int run_verify_log(const std::string& path, int64_t expected) {
  sg::logger::LogReader log(path);  // not lcm::LogFile: it crashes on a damaged event length
  Tally tally;
  sg::logger::LogRecord event;
  while (log.next(event)) tally.add(event.channel, event.data, event.size, 0);
  std::printf("%s: %lld events\n%s%s\n", path.c_str(), static_cast<long long>(log.events()),
              tally.per_channel().c_str(), tally.summary(expected, -1.0).c_str());
  for (const auto& problem : log.problems()) std::printf("damaged: %s\n", problem.text.c_str());
  const bool complete = expected == 0 || tally.intact() == expected;
  const bool clean = tally.corrupt() == 0 && tally.duplicates() == 0 && log.problem_count() == 0;
  return complete && clean ? 0 : 1;
}

struct HostileOptions {
  sg::bus_check::HostileSettings settings;
  double rate_hz = 2000.0;
  std::vector<std::string> channels;
  int64_t first = 0;
  int64_t last = std::numeric_limits<int64_t>::max();
  bool list = false;
  int64_t describe = -1;
  std::string save;
};

/// --list and --describe N [--save FILE]: what the attack would send, without a bus.
int show_hostile(const sg::bus_check::HostilePlan& plan, const HostileOptions& options) {
  std::string channel;
  if (options.list) {
    for (int64_t n = 0; n < plan.total(); ++n) {
      const sg::bus_check::HostilePacket* p = plan.at(n, &channel);
      std::printf("%lld %s %zu %s\n", static_cast<long long>(n), channel.c_str(), p->bytes.size(),
                  p->what.c_str());
    }
    return 0;
  }
  const sg::bus_check::HostilePacket* p = plan.at(options.describe, &channel);
  if (p == nullptr) throw std::runtime_error("no packet " + std::to_string(options.describe));
  std::printf("%lld %s %zu %s\n", static_cast<long long>(options.describe), channel.c_str(),
              p->bytes.size(), p->what.c_str());
  if (!options.save.empty()) {
    std::ofstream out(options.save, std::ios::binary);
    out.write(reinterpret_cast<const char*>(p->bytes.data()),
              static_cast<std::streamsize>(p->bytes.size()));
    if (!out) throw std::runtime_error("cannot write " + options.save);
  }
  return 0;
}

int run_hostile(sg::Bus& bus, sg::bus_check::HostilePlan& plan, const HostileOptions& options) {
  const int64_t total = plan.total();
  std::fprintf(stderr, "hostile: %lld packets on %zu channels at %.0f/s (seed %llu, K = %d)\n",
               static_cast<long long>(total), plan.channels.size(), options.rate_hz,
               static_cast<unsigned long long>(options.settings.seed),
               options.settings.random_bodies);
  const auto start = steady_clock::now();
  const int64_t sent = sg::bus_check::run_attack(
      plan, options.first, options.last, options.rate_hz,
      [&](const std::string& channel, const sg::bus_check::HostilePacket& p) {
        return bus.publish_raw(channel, p.bytes.data(), static_cast<int>(p.bytes.size()));
      },
      [](int64_t done, int64_t due) {
        std::fprintf(stderr, "hostile: %lld of %lld sent\n", static_cast<long long>(done),
                     static_cast<long long>(due));
      },
      [] { return sg::shutdown_requested(); });
  const double seconds = duration<double>(steady_clock::now() - start).count();
  std::printf("hostile: sent %lld packets in %.2f s (%lld publish errors)\n%s",
              static_cast<long long>(sent), seconds, static_cast<long long>(bus.publish_errors()),
              sg::bus_check::attack_summary(plan).c_str());
  return bus.publish_errors() == 0 ? 0 : 1;
}

struct HealthOptions {
  double duration_s = 3.0;
  bool watch = false;
};

/// `health`: the process table and clock offsets after `duration_s`, or (--watch) the events as
/// they come. Exit 1 when a clock is off by more than the loop tolerates or a process is silent.
int run_health(sg::Bus& bus, const HealthOptions& o) {
  sg::ProcessWatch watch;
  bus.subscribe<stereograsp::process_status_t>(
      "PROCESS_STATUS", [&](const stereograsp::process_status_t& s, const sg::ReceiveInfo& info) {
        watch.receive(s, info.recv_utime);
      });
  bus.announce("sg-bus-check");
  char name[256] = {};
  const std::string self_host = gethostname(name, sizeof name - 1) == 0 ? name : "?";
  const auto end = steady_clock::now() + duration<double>(o.duration_s);
  std::set<std::string> warned;
  bool trouble = false;
  bus.spin([&] {
    if (!o.watch) return steady_clock::now() < end;
    for (const auto& e : watch.check(sg::now_utime())) {
      std::printf("%s\n", e.line.c_str());
      trouble |= e.kind == sg::ProcessWatch::Event::kStoppedBeating;
    }
    for (const auto& w : sg::clock_warnings(watch.host_offsets(self_host), self_host)) {
      if (warned.insert(w.substr(0, w.find(" is "))).second)
        std::printf("warning: %s\n", w.c_str());
      trouble = true;
    }
    std::fflush(stdout);
    return true;
  });
  if (o.watch) return trouble ? 1 : 0;
  const int64_t now = sg::now_utime();
  watch.check(now);
  const auto offsets = watch.host_offsets(self_host);
  std::printf("%s\n%s", sg::format_processes(watch, now).c_str(),
              sg::format_clocks(offsets, self_host).c_str());
  for (const auto& w : sg::clock_warnings(offsets, self_host)) {
    std::printf("warning: %s\n", w.c_str());
    trouble = true;
  }
  for (const auto& p : watch.processes()) trouble |= p.silent;
  return trouble ? 1 : 0;
}

void add_hostile_options(CLI::App& cmd, HostileOptions& o) {
  cmd.add_option("--rate", o.rate_hz, "packets per second (not a flood)")
      ->check(CLI::Range(1.0, 1e6))
      ->capture_default_str();
  cmd.add_option("--seed", o.settings.seed, "seed of the random bodies")->capture_default_str();
  cmd.add_option("--random-bodies", o.settings.random_bodies, "random bodies per type (K)")
      ->check(CLI::Range(0, 10000000))
      ->capture_default_str();
  cmd.add_option("--channels", o.channels, "only these channels (comma-separated)")->delimiter(',');
  cmd.add_flag("!--no-windows", o.settings.windows, "leave out the 4-byte windows");
  cmd.add_flag("!--no-truncations", o.settings.truncations, "leave out the truncations");
  cmd.add_flag("!--no-foreign", o.settings.foreign, "leave out the other types' messages");
  cmd.add_option("--first", o.first, "send from packet number N (see --list)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--last", o.last, "send up to packet number N, inclusive");
  cmd.add_flag("--list", o.list, "print every packet: number, channel, size, how it was made");
  cmd.add_option("--describe", o.describe, "print packet number N (with --save: write its bytes)");
  cmd.add_option("--save", o.save, "with --describe: the file to write the packet to");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Checks an LCM bus end to end with every stereograsp message type.", "sg-bus-check"};
  app.require_subcommand(1);
  sg::CommonOptions common;
  sg::add_common_options(app, common);

  SendOptions send;
  CLI::App* send_cmd = app.add_subcommand("send", "Publish check messages on BUS_CHECK_<TYPE>");
  const auto keys = sg::declared_keys(sg::bus_check::read_send_settings);
  common.flags.add(*send_cmd, "--count", "bus_check.count", keys);
  common.flags.add(*send_cmd, "--rate", "bus_check.rate_hz", keys);
  send_cmd->add_option("--duration", send.duration_s, "stop after this many seconds (0: no limit)")
      ->check(CLI::NonNegativeNumber);

  ReceiveOptions receive;
  CLI::App* receive_cmd =
      app.add_subcommand("receive", "Check messages arriving on BUS_CHECK_<TYPE>; exit 1 on loss");
  receive_cmd->add_option("--count", receive.count,
                          "messages to wait for, 0 to run until interrupted");
  receive_cmd->add_option("--timeout", receive.timeout_s,
                          "give up after this many seconds without a message (0: never)");

  std::string log_path;
  int64_t log_count = 0;
  CLI::App* verify_cmd =
      app.add_subcommand("verify-log", "Check a log that lcm-logger recorded of a send");
  verify_cmd->add_option("LOG", log_path, "the LCM log file")->required();
  verify_cmd->add_option("--count", log_count, "messages the log must hold intact (0: any)");

  HostileOptions hostile;
  CLI::App* hostile_cmd = app.add_subcommand(
      "hostile", "Publish hostile packets of every type on the channels the system reads");
  add_hostile_options(*hostile_cmd, hostile);

  HealthOptions health;
  CLI::App* health_cmd = app.add_subcommand(
      "health", "Show every process on the bus (PROCESS_STATUS) and the hosts' clock offsets");
  health_cmd->add_option("--duration", health.duration_s, "seconds to listen before the table")
      ->check(CLI::Range(0.5, 3600.0))
      ->capture_default_str();
  health_cmd->add_flag("--watch", health.watch,
                       "run until interrupted, printing processes that join, stop beating, come "
                       "back or stop, and clock warnings");

  return sg::run_program(app, argc, argv, [&] {
    const sg::Config config = sg::load_common(common);
    if (*verify_cmd) return run_verify_log(log_path, log_count);
    if (*health_cmd) {
      sg::install_shutdown_handlers();
      sg::Bus bus(common.lcm_url);
      return run_health(bus, health);
    }
    if (*hostile_cmd) {
      sg::bus_check::HostilePlan plan =
          sg::bus_check::plan_attack(hostile.channels, hostile.settings);
      if (hostile.list || hostile.describe >= 0) return show_hostile(plan, hostile);
      sg::install_shutdown_handlers();
      sg::Bus bus(common.lcm_url);
      return run_hostile(bus, plan, hostile);
    }

    const sg::bus_check::SendSettings settings = sg::bus_check::read_send_settings(config);
    send.count = settings.count;
    send.rate_hz = settings.rate_hz;

    sg::install_shutdown_handlers();
    sg::Bus bus(common.lcm_url);
    return *send_cmd ? run_send(bus, send) : run_receive(bus, receive);
  });
}
