#include "lab/supervisor.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace sg::lab {
namespace {

using Clock = std::chrono::steady_clock;

/// Every event line the supervisor writes: "sg-lab: <name> <what>".
void say(const SupervisorOptions& o, const std::string& what) {
  std::fprintf(stderr, "sg-lab: %s %s\n", o.name.c_str(), what.c_str());
  std::fflush(stderr);
}

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", s);
  return text;
}

/// The signals the supervisor waits for; blocked, so they queue for sigtimedwait.
sigset_t watched_signals() {
  sigset_t set;
  sigemptyset(&set);
  for (int s : {SIGINT, SIGTERM, SIGHUP, SIGCHLD}) sigaddset(&set, s);
  return set;
}

/// Starts the process with the signal mask the supervisor had before it blocked its own.
pid_t start(const SupervisorOptions& o, const sigset_t& original_mask) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  sigprocmask(SIG_SETMASK, &original_mask, nullptr);
  for (const std::string& e : o.env) {  // the supervisor is single-threaded: setenv is safe
    const size_t eq = e.find('=');
    if (eq != std::string::npos) setenv(e.substr(0, eq).c_str(), e.c_str() + eq + 1, 1);
  }
  std::vector<char*> args;
  for (const std::string& a : o.argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  execvp(args[0], args.data());
  std::fprintf(stderr, "sg-lab: %s: cannot run %s: %s\n", o.name.c_str(), o.argv[0].c_str(),
               std::strerror(errno));
  _exit(127);
}

/// What happened while waiting.
struct Wait {
  enum Kind { kExited, kStop, kRestart, kTimeout } kind;
  int status = 0;  ///< the wait status, when kExited
};

/// Waits up to `timeout_s` (infinite when negative) for the child to exit or a signal.
Wait wait_for(pid_t child, double timeout_s, const sigset_t& set) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(std::max(timeout_s, 0.0)));
  while (true) {
    int status = 0;
    if (child > 0 && waitpid(child, &status, WNOHANG) == child) return {Wait::kExited, status};
    timespec ts{1, 0};
    if (timeout_s >= 0) {
      const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
      if (left <= 0) return {Wait::kTimeout};
      ts.tv_sec = static_cast<time_t>(std::min(left, 1.0));
      ts.tv_nsec = static_cast<long>((std::min(left, 1.0) - static_cast<double>(ts.tv_sec)) * 1e9);
    }
    siginfo_t info{};
    const int sig = sigtimedwait(&set, &info, &ts);
    if (sig == SIGINT || sig == SIGTERM) return {Wait::kStop};
    if (sig == SIGHUP) return {Wait::kRestart};
  }
}

/// SIGINT, then SIGTERM, then SIGKILL, `stop_timeout` apart, until the child exits; returns its
/// wait status. A second stop request while stopping escalates at once.
int stop(const SupervisorOptions& o, pid_t child, const sigset_t& set) {
  for (int sig : {SIGINT, SIGTERM, SIGKILL}) {
    kill(child, sig);
    while (true) {
      const Wait w = wait_for(child, sig == SIGKILL ? -1 : o.stop_timeout, set);
      if (w.kind == Wait::kExited) return w.status;
      if (w.kind == Wait::kTimeout || w.kind == Wait::kStop) break;
    }
    if (sig != SIGKILL)
      say(o, "did not stop on " + std::string(sigabbrev_np(sig)) + " within " +
                 seconds(o.stop_timeout) + "; sending the next signal");
  }
  return 0;
}

bool failed(int status) { return !(WIFEXITED(status) && WEXITSTATUS(status) == 0); }

int exit_code(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 1;
}

}  // namespace

std::string describe_exit(int status) {
  if (WIFEXITED(status)) return "status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status))
    return "signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
  return "wait status " + std::to_string(status);
}

int supervise(const SupervisorOptions& o) {
  const sigset_t set = watched_signals();
  sigset_t original;
  sigprocmask(SIG_BLOCK, &set, &original);
  double backoff = 1;
  int restarts = 0;
  while (true) {
    const auto started = Clock::now();
    const pid_t child = start(o, original);
    if (child < 0) {
      say(o, std::string("cannot start: fork: ") + std::strerror(errno));
      return 1;
    }
    say(o, "started (pid " + std::to_string(child) + ")");
    const Wait w = wait_for(child, -1, set);
    if (w.kind == Wait::kStop) {
      const int status = stop(o, child, set);
      say(o, "stopped (" + describe_exit(status) + ")");
      return 0;
    }
    if (w.kind == Wait::kRestart) {
      say(o, "restarting on request (" + describe_exit(stop(o, child, set)) + ")");
      backoff = 1;
      continue;
    }
    const double ran = std::chrono::duration<double>(Clock::now() - started).count();
    if (ran >= o.reset_after) backoff = 1;
    const bool again = o.restart == RestartPolicy::kAlways ||
                       (o.restart == RestartPolicy::kOnFailure && failed(w.status));
    if (!again) {
      say(o, "exited with " + describe_exit(w.status) + " after " + seconds(ran) +
                 "; not restarted (restart: " + to_string(o.restart) + ")");
      return exit_code(w.status);
    }
    say(o, "exited with " + describe_exit(w.status) + " after " + seconds(ran) +
               "; restarting in " + seconds(backoff) + " (restart " + std::to_string(++restarts) +
               ")");
    const Wait pause = wait_for(-1, backoff, set);
    if (pause.kind == Wait::kStop) {
      say(o, "stopped while waiting to restart");
      return 0;
    }
    backoff = std::min(backoff * 2, o.max_backoff);
  }
}

}  // namespace sg::lab
