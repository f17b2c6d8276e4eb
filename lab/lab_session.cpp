#include "lab/lab_session.hpp"

#include <unistd.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "auth/data_auth.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/process_watch.hpp"
#include "common/shutdown.hpp"
#include "lab/host_shell.hpp"
#include "lab/lab_credentials.hpp"

namespace sg::lab {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;
constexpr const char* kBin = "build/bin";
constexpr double kShellTimeout = 20;

double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string fixed(double v, int decimals = 1) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}

/// "<lab>-20261205-081500": a session's folder, by the local clock.
std::string session_name(const std::string& lab) {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  return lab + "-" + stamp;
}

std::string this_hostname() {
  char name[256] = {};
  return gethostname(name, sizeof name - 1) == 0 ? name : "?";
}

}  // namespace

/// The bus as sg-lab sees it: PROCESS_STATUS into a ProcessWatch; for `status` and `watch`,
/// sg-lab announced itself, so that it takes part in the clock exchange (`up` only listens: its
/// ssh calls would leave gaps in its heartbeats that a recorded session would list).
class LabSession::Listener {
 public:
  Listener(const std::string& url, bool take_part, const std::optional<auth::LabKey>& key)
      : bus(url) {
    if (key)
      bus.set_guard(
          std::make_shared<auth::DataGuard>(auth::credentials_from_lab_key(*key, "sg-lab")));
    bus.subscribe<stereograsp::process_status_t>(
        "PROCESS_STATUS", [this](const stereograsp::process_status_t& s, const ReceiveInfo& info) {
          watch.receive(s, info.recv_utime);
        });
    if (take_part) bus.announce("sg-lab");
  }
  /// Handles messages for `seconds`.
  void listen(double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end && !shutdown_requested()) bus.handle(std::chrono::milliseconds(50));
  }
  Bus bus;
  ProcessWatch watch;
};

ProcessSpec recorder_process(const LabFile& lab, const std::string& session) {
  ProcessSpec p;
  p.name = "recorder";
  p.host = lab.recorder.host;
  p.run = {"lcm-logger", "--quiet", "--append"};
  if (!lab.bus.empty()) p.run.push_back("--lcm-url=" + lab.bus);
  if (!lab.recorder.exclude.empty()) {
    p.run.push_back("--invert-channels");
    p.run.push_back("--channel=" + lab.recorder.exclude);
  }
  p.run.push_back("logs/" + session + "/session.lcmlog");
  p.ready = Readiness::kStarted;
  p.restart = RestartPolicy::kOnFailure;
  return p;
}

LabSession::LabSession(LabFile lab, std::string project, std::ostream& out, std::string state)
    : lab_(std::move(lab)),
      project_(std::move(project)),
      state_(state.empty() ? project_ + "/logs" : std::move(state)),
      out_(out) {
  for (HostSpec& h : lab_.hosts)  // this machine's processes report its own name
    if (h.local() && !h.hostname_given) h.hostname = this_hostname();
}

LabSession::~LabSession() = default;

LabSession::Listener& LabSession::listener(bool take_part) {
  if (!listener_) listener_ = std::make_unique<Listener>(lab_.bus, take_part, current_key());
  return *listener_;
}

std::vector<std::string> LabSession::argv_of(const ProcessSpec& p) const {
  std::vector<std::string> argv = p.run;
  if (!p.stereograsp()) return argv;
  if (argv[0].find('/') == std::string::npos) argv[0] = std::string(kBin) + "/" + argv[0];
  if (!lab_.bus.empty()) argv.insert(argv.begin() + 1, {"--lcm-url", lab_.bus});
  if (!lab_.config.empty()) argv.insert(argv.begin() + 1, {"--config", lab_.config});
  if (identity_of(p).empty() || names_its_key(p)) return argv;
  const auto credentials = credentials_.find(p.name);
  if (credentials != credentials_.end())
    argv.insert(argv.begin() + 1, {"--key", credentials->second});
  else if (!lab_key_)
    argv.insert(argv.begin() + 1, "--insecure-no-key");
  return argv;
}

// ---- the state file -------------------------------------------------------------------------

void LabSession::save_state() const {
  const fs::path folder = fs::path(state_) / session_;
  fs::create_directories(folder);
  std::ofstream f(folder / "sg-lab.state");
  for (const StartedProcess& s : started_)
    f << s.name << '\t' << s.host << '\t' << s.pid << '\t' << s.log << '\n';
  const fs::path current = fs::path(state_) / (lab_.lab + ".current");
  std::error_code ec;
  fs::remove(current, ec);
  fs::create_symlink(session_, current, ec);
}

void LabSession::load_state() {
  const fs::path current = fs::path(state_) / (lab_.lab + ".current");
  std::error_code ec;
  const fs::path target = fs::read_symlink(current, ec);
  if (ec) throw LabError("lab '" + lab_.lab + "' is not up (no " + current.string() + ")");
  // (the state folder: --state, else logs/ of this checkout)
  session_ = target.filename().string();
  std::ifstream f(fs::path(state_) / session_ / "sg-lab.state");
  if (!f) throw LabError("lab '" + lab_.lab + "': session " + session_ + " has no sg-lab.state");
  started_.clear();
  std::string line;
  while (std::getline(f, line)) {
    std::istringstream row(line);
    StartedProcess s;
    std::string pid;
    if (std::getline(row, s.name, '\t') && std::getline(row, s.host, '\t') &&
        std::getline(row, pid, '\t') && std::getline(row, s.log)) {
      s.pid = std::strtol(pid.c_str(), nullptr, 10);
      if (s.pid > 0) started_.push_back(s);
    }
  }
}

// ---- processes on their hosts ---------------------------------------------------------------

bool LabSession::alive(const StartedProcess& s) {
  // The pid is ours only while its command line is the supervisor of this process.
  const std::string check = "tr '\\0' ' ' < /proc/" + std::to_string(s.pid) +
                            "/cmdline 2>/dev/null | grep -q -- " +
                            shell_quote("supervise --name " + s.name + " ");
  return make_shell(lab_.host(s.host), project_)->run(check, kShellTimeout).ok();
}

std::set<std::string> LabSession::running() {
  std::map<std::string, std::string> checks;  // host -> one command for all its processes
  for (const StartedProcess& s : started_)
    checks[s.host] +=
        "tr '\\0' ' ' < /proc/" + std::to_string(s.pid) + "/cmdline 2>/dev/null | grep -q -- " +
        shell_quote("supervise --name " + s.name + " ") + " && echo " + shell_quote(s.name) + "; ";
  std::set<std::string> names;
  for (const auto& [host, command] : checks) {
    const CommandResult r =
        make_shell(lab_.host(host), project_)->run(command + "true", kShellTimeout);
    std::istringstream lines(r.output);
    for (std::string name; std::getline(lines, name);) names.insert(name);
  }
  return names;
}

std::string LabSession::log_tail(const StartedProcess& s, int lines) {
  const CommandResult r =
      make_shell(lab_.host(s.host), project_)
          ->run("tail -n " + std::to_string(lines) + " " + shell_quote(s.log), kShellTimeout);
  return r.ok() ? r.output : r.describe() + "\n";
}

void LabSession::start(const ProcessSpec& p) {
  const auto t0 = Clock::now();
  const double stamp = static_cast<double>(now_utime());
  StartedProcess s{p.name, p.host, 0, "logs/" + session_ + "/" + p.name + ".log"};
  // Only the supervisor goes to the background, its output to the log: nothing of it holds the
  // shell's (or ssh's) output open, so the command returns at once with its pid.
  std::string command = "mkdir -p logs/" + shell_quote(session_) + " && { setsid " +
                        std::string(kBin) + "/sg-lab supervise --name " + shell_quote(p.name) +
                        " --restart " + to_string(p.restart) + " --stop-timeout " +
                        fixed(lab_.stop_timeout, 3);
  for (const auto& [name, value] : p.env) command += " --env " + shell_quote(name + "=" + value);
  command += " --";
  for (const std::string& a : argv_of(p)) command += " " + shell_quote(a);
  command += " </dev/null >>" + shell_quote(s.log) + " 2>&1 & echo $!; }";
  const CommandResult r = make_shell(lab_.host(p.host), project_)->run(command, kShellTimeout);
  s.pid = r.ok() ? std::strtol(r.output.c_str(), nullptr, 10) : 0;
  if (s.pid <= 0) throw LabError("process '" + p.name + "' on " + p.host + ": " + r.describe());
  started_.push_back(s);
  save_state();
  wait_ready(p, s, stamp);
  out_ << "sg-lab: " << p.name << " ready on " << p.host << " in " << fixed(since(t0)) << " s\n"
       << std::flush;
}

void LabSession::wait_ready(const ProcessSpec& p, const StartedProcess& s, double) {
  const HostSpec& host = lab_.host(p.host);
  std::set<std::string> before;
  for (const auto& known : listener().watch.processes()) before.insert(known.name);
  const auto t0 = Clock::now();
  auto next_check = t0 + std::chrono::seconds(1);
  while (since(t0) < lab_.ready_timeout && !shutdown_requested()) {
    listener().listen(0.1);
    if (p.ready == Readiness::kStatus) {
      for (const auto& q : listener().watch.processes())
        if (!before.count(q.name) && q.last.process == p.program() &&
            q.last.host == host.hostname &&
            q.last.state == stereograsp::process_status_t::STATE_READY)
          return;
    }
    if (Clock::now() < next_check) continue;
    next_check = Clock::now() + std::chrono::seconds(1);
    const bool running = alive(s);
    const std::string tail = running ? "" : log_tail(s, 15);
    if (!running)
      throw LabError("process '" + p.name + "' on " + p.host + " exited; its log (" + s.log +
                     "):\n" + tail);
    if (p.ready == Readiness::kStarted && log_tail(s, 5).find("exited with") == std::string::npos)
      return;
  }
  std::string heard;
  for (const auto& q : listener().watch.processes())
    if (q.last.process == p.program()) heard += " " + q.name;
  throw LabError("process '" + p.name + "' on " + p.host + " did not report ready within " +
                 fixed(lab_.ready_timeout) + " s (waiting for PROCESS_STATUS from " + p.program() +
                 " at host '" + host.hostname + "'" +
                 (heard.empty() ? "" : "; heard:" + heard + " — is hosts[].hostname right?") +
                 "); its log (" + s.log + "):\n" + log_tail(s, 15));
}

void LabSession::stop(const StartedProcess& s, bool& killed) {
  auto shell = make_shell(lab_.host(s.host), project_);
  if (!alive(s)) {
    out_ << "sg-lab: " << s.name << " on " << s.host << " had already exited\n";
    return;
  }
  shell->run("kill -INT " + std::to_string(s.pid), kShellTimeout);
  const auto t0 = Clock::now();
  const double patience = 2 * lab_.stop_timeout + 2;  // the supervisor escalates by itself
  while (since(t0) < patience && alive(s))
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  if (alive(s)) {
    shell->run("kill -KILL -- -" + std::to_string(s.pid), kShellTimeout);  // its group
    killed = true;
    out_ << "sg-lab: " << s.name << " on " << s.host << " did not stop; killed\n";
    return;
  }
  out_ << "sg-lab: " << s.name << " stopped on " << s.host << " in " << fixed(since(t0)) << " s\n"
       << std::flush;
}

// ---- up --------------------------------------------------------------------------------------

void LabSession::preflight() {
  // One call per host: it answers, and every program it is to run is there. Each missing thing
  // is printed as "missing <what>".
  std::map<std::string, std::string> checks;
  for (const HostSpec& h : lab_.hosts)
    checks[h.name] =
        "test -x " + std::string(kBin) + "/sg-lab || echo 'missing " + kBin + "/sg-lab'; ";
  for (const ProcessSpec& p : lab_.processes) {
    const std::string program = argv_of(p)[0];
    checks[p.host] += (p.stereograsp() ? "test -x " + shell_quote(program)
                                       : "command -v " + shell_quote(program) + " >/dev/null") +
                      " || echo " +
                      shell_quote("missing " + program + " (process " + p.name + ")") + "; ";
  }
  for (const HostSpec& h : lab_.hosts) {
    const CommandResult r = make_shell(h, project_)->run(checks[h.name] + "true", kShellTimeout);
    if (!r.ok())
      throw LabError("host '" + h.name + "' (" + h.destination() + ":" + std::to_string(h.port) +
                     ") is unreachable: " + r.describe());
    if (const size_t at = r.output.find("missing "); at != std::string::npos) {
      const std::string what = r.output.substr(at + 8, r.output.find('\n', at) - at - 8);
      throw LabError(lab_.path + ": host '" + h.name + "': no " + what + " in " +
                     (h.path.empty() ? project_ : h.path) +
                     (what.find("sg-") != std::string::npos ? " (build the project there)"
                                                            : " (not on its PATH)"));
    }
  }
  for (const ProcessSpec& p : lab_.processes)
    for (const std::string& f : p.files)
      if (!fs::exists(fs::path(project_) / f))
        throw LabError(lab_.path + ":" + std::to_string(p.line) + ": process '" + p.name +
                       "': no file " + f + " in " + project_);
  if (!lab_.config.empty() && !fs::exists(fs::path(project_) / lab_.config))
    throw LabError(lab_.path + ": config " + lab_.config + " is not in " + project_);
}

void LabSession::copy_files() {
  std::map<std::string, std::set<std::string>> wanted;  // host -> files
  for (const ProcessSpec& p : lab_.processes) {
    if (!lab_.config.empty() && p.stereograsp()) wanted[p.host].insert(lab_.config);
    for (const std::string& f : p.files) wanted[p.host].insert(f);
  }
  for (const auto& [host, files] : wanted) {
    auto shell = make_shell(lab_.host(host), project_);
    const CommandResult r = shell->copy_all(project_, {files.begin(), files.end()}, kShellTimeout);
    if (!r.ok()) throw LabError("copying files to " + host + ": " + r.describe());
    out_ << "sg-lab: " << files.size() << " file(s) on " << host << " up to date\n";
  }
}

uint32_t LabSession::generation() const {
  std::ifstream f(fs::path(state_) / (lab_.lab + ".generation"));
  unsigned long g = 0;
  return f >> g && g < 0xffffffffUL ? static_cast<uint32_t>(g) : 0;
}

std::optional<auth::LabKey> LabSession::current_key() const {
  if (!lab_key_) return std::nullopt;
  return auth::generation_key(*lab_key_, generation());
}

void LabSession::distribute_credentials(const std::string& skip) {
  credentials_.clear();
  if (!lab_key_) {
    out_ << "sg-lab: INSECURE: no lab key: every process starts with --insecure-no-key\n";
    return;
  }
  const std::string stage = state_ + "/" + session_ + "/stage";
  LabFile others = lab_;
  std::erase_if(others.processes, [&](const ProcessSpec& p) { return p.name == skip; });
  const auto paths = stage_credentials(others, *current_key(), session_, stage);
  std::map<std::string, std::vector<std::string>> by_host;
  for (const ProcessSpec& p : lab_.processes)
    if (paths.count(p.name) != 0) by_host[p.host].push_back(paths.at(p.name));
  for (const auto& [host, files] : by_host) {
    const CommandResult r =
        make_shell(lab_.host(host), project_)->copy_all(stage, files, kShellTimeout);
    if (!r.ok()) throw LabError("copying credentials to " + host + ": " + r.describe());
  }
  std::error_code ec;
  fs::remove_all(stage, ec);  // the hosts have them; the lab key can make them again
  credentials_ = paths;
  out_ << "sg-lab: credentials for " << paths.size() << " process(es) on " << by_host.size()
       << " host(s)\n";
}

void LabSession::up() {
  const auto t0 = Clock::now();
  try {
    load_state();
    for (const StartedProcess& s : started_)
      if (alive(s))
        throw LabError("lab '" + lab_.lab + "' is already up (session " + session_ +
                       "): sg-lab status, or sg-lab down first");
  } catch (const LabError& e) {
    if (std::string(e.what()).find("already up") != std::string::npos) throw;
  }
  started_.clear();
  preflight();
  session_ = session_name(lab_.lab);
  copy_files();
  distribute_credentials();
  out_ << "sg-lab: lab '" << lab_.lab << "', session " << session_ << "\n" << std::flush;
  listener();  // listening before anything starts
  try {
    if (lab_.recorder.enabled) start(recorder_process(lab_, session_));
    for (const ProcessSpec& p : lab_.processes) start(p);
  } catch (const LabError&) {
    if (!started_.empty()) {
      out_ << "sg-lab: stopping what was started\n";
      try {
        down();
      } catch (const LabError& e) {  // the first error is the one to report
        out_ << "sg-lab: " << e.what() << "\n";
      }
    }
    throw;
  }
  save_state();
  out_ << "sg-lab: up in " << fixed(since(t0)) << " s: " << lab_.processes.size()
       << " processes on " << lab_.hosts.size() << " host(s)"
       << (lab_.recorder.enabled
               ? ", recording to " + lab_.recorder.host + ":logs/" + session_ + "/session.lcmlog"
               : "")
       << "\n"
       << std::flush;
}

// ---- down, restart ----------------------------------------------------------------------------

int LabSession::down() {
  if (started_.empty()) load_state();
  bool killed = false;
  for (auto s = started_.rbegin(); s != started_.rend(); ++s) stop(*s, killed);
  report_session();
  std::error_code ec;
  fs::remove(fs::path(state_) / (lab_.lab + ".current"), ec);
  return killed ? 1 : 0;
}

void LabSession::report_session() {
  if (!lab_.recorder.enabled) return;
  const std::string log = "logs/" + session_ + "/session.lcmlog";
  out_ << "sg-lab: session log: " << lab_.recorder.host << ":" << log << "\n" << std::flush;
  const CommandResult r = make_shell(lab_.host(lab_.recorder.host), project_)
                              ->run(std::string(kBin) + "/sg-report " + shell_quote(log) +
                                        " --no-plots --no-csv 2>&1 | grep -v '^sg-report: reading'",
                                    120);
  out_ << r.output << std::flush;
}

void LabSession::restart(const std::string& name) {
  load_state();
  const ProcessSpec* p = lab_.process(name);
  const ProcessSpec recorder = recorder_process(lab_, session_);
  if (name == "recorder") p = &recorder;
  for (const StartedProcess& s : started_) {
    if (s.name != name) continue;
    if (!p) throw LabError("process '" + name + "' is not in " + lab_.path);
    if (!alive(s)) throw LabError("process '" + name + "' on " + s.host + " is not running");
    listener().listen(0.2);
    make_shell(lab_.host(s.host), project_)
        ->run("kill -HUP " + std::to_string(s.pid), kShellTimeout);
    const auto t0 = Clock::now();
    wait_ready(*p, s, 0);
    out_ << "sg-lab: " << name << " restarted on " << s.host << " in " << fixed(since(t0))
         << " s\n";
    return;
  }
  throw LabError("no process '" + name + "' in session " + session_);
}

void LabSession::revoke(const std::string& name) {
  load_state();
  if (!lab_key_) throw LabError("revoke needs the lab key (--key, $SG_LAB_KEY)");
  const ProcessSpec* p = lab_.process(name);
  if (!p || identity_of(*p).empty())
    throw LabError("no process '" + name + "' with credentials in " + lab_.path);
  bool killed = false;
  for (const StartedProcess& s : started_)
    if (s.name == name) stop(s, killed);
  std::erase_if(started_, [&](const StartedProcess& s) { return s.name == name; });
  save_state();
  const uint32_t next = generation() + 1;
  std::ofstream(fs::path(state_) / (lab_.lab + ".generation")) << next << "\n";
  distribute_credentials(name);
  make_shell(lab_.host(p->host), project_)
      ->run("rm -f " + shell_quote(credentials_path(session_, name)), kShellTimeout);
  out_ << "sg-lab: " << name << " revoked: stopped, its credentials deleted on " << p->host
       << "; the lab's keys are now of generation " << next << "\n"
       << std::flush;
  for (const ProcessSpec& q : lab_.processes) {
    const bool running = std::any_of(started_.begin(), started_.end(),
                                     [&](const StartedProcess& s) { return s.name == q.name; });
    if (running && credentials_.count(q.name) != 0) restart(q.name);
  }
}

int LabSession::logs(const std::string& name, int lines) {
  load_state();
  for (const StartedProcess& s : started_)
    if (s.name == name) {
      out_ << log_tail(s, lines) << std::flush;
      return 0;
    }
  throw LabError("no process '" + name + "' in session " + session_);
}

// ---- status, watch ----------------------------------------------------------------------------

int LabSession::status(double listen_s) {
  load_state();
  Listener& l = listener(true);
  l.listen(listen_s);
  const int64_t now = now_utime();
  l.watch.check(now);
  bool healthy = true;
  char line[512];
  std::snprintf(line, sizeof line, "%-12s %-10s %-16s %8s %-12s %8s %8s %8s %5s %9s  %s\n", "NAME",
                "HOST", "PROGRAM", "PID", "STATE", "UP", "IN/s", "OUT/s", "BAD", "UNVOUCHED",
                "LAST PROBLEM");
  out_ << "lab '" << lab_.lab << "', session " << session_ << "\n" << line;
  const std::set<std::string> up = running();
  for (const StartedProcess& s : started_) {
    const ProcessSpec recorder = recorder_process(lab_, session_);
    const ProcessSpec* p = s.name == "recorder" ? &recorder : lab_.process(s.name);
    if (!p) continue;
    const HostSpec& host = lab_.host(s.host);
    const ProcessWatch::Process* seen = nullptr;
    for (const auto& q : l.watch.processes())
      if (q.last.process == p->program() && q.last.host == host.hostname &&
          (!seen || q.last_heard > seen->last_heard))
        seen = &q;
    const bool running = up.count(s.name) > 0;
    std::string state = running ? "running" : "exited";
    std::string uptime = "-", in = "-", out = "-", bad = "-", unvouched = "-", problem, pid = "-";
    if (seen && running) {
      const auto& st = seen->last;
      const double silence = (now - seen->last_heard) / 1e6;
      state = silence >= ProcessWatch::kSilentAfter ? "silent " + fixed(silence) + " s"
                                                    : state_name(st.state);
      uptime = fixed((st.utime - st.start_utime) / 1e6 + silence, 0) + " s";
      double rin = 0, rout = 0;
      for (double r : st.rate_in_hz) rin += r;
      for (double r : st.rate_out_hz) rout += r;
      in = fixed(rin), out = fixed(rout);
      bad = std::to_string(st.decode_errors + st.refused_inputs + st.handler_errors);
      unvouched = st.vouched_as.empty() ? "insecure" : std::to_string(st.unvouched_inputs);
      problem = st.state_detail.empty() ? st.last_problem : st.state_detail;
      pid = std::to_string(st.pid);
      healthy &= state == "ready";
    } else if (running && p->ready == Readiness::kStatus) {
      state = "no status";
      healthy = false;
    } else if (!running) {
      healthy = false;
      problem = "its supervisor is gone (sg-lab logs " + s.name + ")";
    }
    std::snprintf(line, sizeof line, "%-12s %-10s %-16s %8s %-12s %8s %8s %8s %5s %9s  %s\n",
                  s.name.c_str(), s.host.c_str(), p->program().c_str(), pid.c_str(), state.c_str(),
                  uptime.c_str(), in.c_str(), out.c_str(), bad.c_str(), unvouched.c_str(),
                  problem.substr(0, 160).c_str());
    out_ << line;
  }
  const std::string self = this_hostname();
  const auto offsets = l.watch.host_offsets(self);
  out_ << "\n" << format_clocks(offsets, self);
  for (const std::string& w : clock_warnings(offsets, self)) {
    out_ << "warning: " << w << "\n";
    healthy = false;
  }
  out_ << std::flush;
  return healthy ? 0 : 1;
}

int LabSession::watch() {
  load_state();
  Listener& l = listener(true);
  const std::string self = this_hostname();
  std::set<std::string> warned, gone;
  auto next_check = Clock::now();
  int status = 0;
  while (!shutdown_requested()) {
    l.listen(0.2);
    for (const auto& e : l.watch.check(now_utime())) {
      out_ << e.line << "\n";
      if (e.kind == ProcessWatch::Event::kStoppedBeating) status = 1;
    }
    for (const std::string& w : clock_warnings(l.watch.host_offsets(self), self))
      if (warned.insert(w.substr(0, w.find(" is "))).second) out_ << "warning: " << w << "\n";
    if (Clock::now() >= next_check) {
      next_check = Clock::now() + std::chrono::seconds(2);
      const std::set<std::string> up = running();
      for (const StartedProcess& s : started_)
        if (!gone.count(s.name) && !up.count(s.name)) {
          gone.insert(s.name);
          out_ << s.name << " on " << s.host << ": its supervisor exited (sg-lab logs " << s.name
               << ")\n";
          status = 1;
        }
    }
    out_ << std::flush;
  }
  return status;
}

}  // namespace sg::lab
