#include "lab/host_shell.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>

namespace sg::lab {
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kMaxOutput = 1 << 20;

/// The child's side of run_argv: stdin from `in`, stdout and stderr to `out`, its own process
/// group (so a time-out kills the command and whatever it started), then exec.
[[noreturn]] void exec_child(const std::vector<std::string>& argv, int in, int out) {
  setpgid(0, 0);
  dup2(in, STDIN_FILENO);
  dup2(out, STDOUT_FILENO);
  dup2(out, STDERR_FILENO);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  execvp(args[0], args.data());
  const std::string why = "cannot run " + argv[0] + ": " + std::strerror(errno) + "\n";
  (void)!write(STDERR_FILENO, why.data(), why.size());
  _exit(127);
}

/// Reads `fd` until it closes or the deadline passes; true if it closed.
bool drain(int fd, std::string& output, Clock::time_point deadline) {
  char buffer[4096];
  while (true) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int r = poll(&p, 1, static_cast<int>(std::min<int64_t>(left, 1000)));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) continue;
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;
    if (output.size() < kMaxOutput) output.append(buffer, static_cast<size_t>(n));
  }
}

/// Waits for `pid` and returns its status as an exit code (128 + signal when killed).
int reap(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

std::string join(const std::vector<std::string>& argv) {
  std::string s;
  for (const std::string& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

/// The environment assignments of a host, for the front of a shell command.
std::string env_prefix(const HostSpec& host) {
  std::string s;
  for (const auto& [key, value] : host.env) s += "export " + key + "=" + shell_quote(value) + "; ";
  return s;
}

class LocalShell final : public HostShell {
 public:
  LocalShell(HostSpec host, std::string project) : host_(std::move(host)) {
    folder_ = host_.path.empty() ? project : host_.path;
  }
  CommandResult run(const std::string& command, double timeout_s) override {
    CommandResult r = run_argv(
        {"sh", "-c", "cd " + shell_quote(folder_) + " || exit 97; " + env_prefix(host_) + command},
        timeout_s);
    r.command = command + " (on " + host_.name + ")";
    return r;
  }
  CommandResult copy(const std::string& local_path, const std::string& remote_path,
                     double timeout_s) override {
    namespace fs = std::filesystem;
    const fs::path to = fs::path(remote_path).is_absolute() ? fs::path(remote_path)
                                                            : fs::path(folder_) / remote_path;
    std::error_code ec;
    if (fs::exists(to, ec) && fs::equivalent(local_path, to, ec)) {
      CommandResult r;
      r.exit_code = 0;
      r.command = "copy " + local_path + " (already there)";
      return r;
    }
    return run("mkdir -p " + shell_quote(to.parent_path().string()) + " && cp " +
                   shell_quote(fs::absolute(local_path).string()) + " " + shell_quote(to.string()),
               timeout_s);
  }
  CommandResult copy_all(const std::string& local_project, const std::vector<std::string>& files,
                         double timeout_s) override {
    namespace fs = std::filesystem;
    CommandResult all;
    all.exit_code = 0;
    for (const std::string& f : files) {
      all = copy((fs::path(local_project) / f).string(), f, timeout_s);
      if (!all.ok()) return all;
    }
    return all;
  }
  const HostSpec& host() const override { return host_; }

 private:
  HostSpec host_;
  std::string folder_;
};

class SshShell final : public HostShell {
 public:
  explicit SshShell(HostSpec host) : host_(std::move(host)) {}

  CommandResult run(const std::string& command, double timeout_s) override {
    std::vector<std::string> argv = ssh_base("ssh", "-p");
    argv.push_back(host_.destination());
    const std::string folder = host_.path.empty() ? "." : shell_quote(host_.path);
    argv.push_back("cd " + folder + " || exit 97; " + env_prefix(host_) + command);
    CommandResult r = run_argv(argv, timeout_s);
    r.command = command + " (on " + host_.name + " over ssh)";
    if (r.exit_code == 255)  // ssh's own failure: say so, not "exit 255"
      r.output = "ssh to " + host_.destination() + ":" + std::to_string(host_.port) +
                 " failed: " + r.output;
    return r;
  }

  CommandResult copy(const std::string& local_path, const std::string& remote_path,
                     double timeout_s) override {
    const std::string parent = std::filesystem::path(remote_path).parent_path().string();
    if (!parent.empty()) {
      CommandResult made = run("mkdir -p " + shell_quote(parent), timeout_s);
      if (!made.ok()) return made;
    }
    std::vector<std::string> argv = ssh_base("scp", "-P");
    argv.push_back("-q");
    argv.push_back(local_path);
    const std::string base = host_.path.empty() ? "" : host_.path + "/";
    const std::string target =
        std::filesystem::path(remote_path).is_absolute() ? remote_path : base + remote_path;
    // Into a new file, then renamed over the old: a host that shares this file system (or a
    // reader of the old file) never sees it truncated.
    const std::string fresh = target + ".sg-lab-new";
    argv.push_back(host_.destination() + ":" + fresh);
    CommandResult r = run_argv(argv, timeout_s);
    r.command = "scp " + local_path + " to " + host_.name + ":" + target;
    if (!r.ok()) return r;
    return run("mv -f " + shell_quote(fresh) + " " + shell_quote(target), timeout_s);
  }

  CommandResult copy_all(const std::string& local_project, const std::vector<std::string>& files,
                         double timeout_s) override {
    // tar of the files as named (absolute ones kept absolute: -P), unpacked in the project's
    // folder there. GNU tar unlinks a file before it writes it anew, so a host that shares
    // this file system, or a process reading the old file, never sees it truncated.
    std::string pack = "cd " + shell_quote(local_project) + " && tar -cPf -";
    for (const std::string& f : files) pack.append(" ").append(shell_quote(f));
    std::vector<std::string> ssh = ssh_base("ssh", "-p");
    ssh.push_back(host_.destination());
    const std::string folder = host_.path.empty() ? "." : shell_quote(host_.path);
    ssh.push_back("cd " + folder + " && tar -xPf -");
    std::string unpack;
    for (const std::string& a : ssh) unpack.append(shell_quote(a)).append(" ");
    CommandResult r =
        run_argv({"bash", "-c", "set -o pipefail; " + pack + " | " + unpack}, timeout_s);
    r.command = "copying " + std::to_string(files.size()) + " file(s) to " + host_.name;
    return r;
  }
  const HostSpec& host() const override { return host_; }

 private:
  /// ssh's (or scp's) options: batch mode, a 5 s connection time-out, and one connection per
  /// host shared by this sg-lab's calls (ControlMaster; each sg-lab its own, kept 15 s after the
  /// last call, so a host that went away meanwhile is never reached through a dead connection):
  /// `up` makes a dozen calls or more, each of which would otherwise pay for a key exchange.
  std::vector<std::string> ssh_base(const std::string& program, const std::string& port_flag) {
    std::vector<std::string> argv = {
        program,
        "-o",
        "BatchMode=yes",
        "-o",
        "ConnectTimeout=5",
        "-o",
        "ControlMaster=auto",
        "-o",
        "ControlPath=" + control_folder() + "/%C-" + std::to_string(getpid()),
        "-o",
        "ControlPersist=15",
        port_flag,
        std::to_string(host_.port)};
    argv.insert(argv.end(), host_.ssh_options.begin(), host_.ssh_options.end());
    return argv;
  }
  /// A folder of this user's only, for ssh's control sockets.
  static std::string control_folder() {
    const std::string folder = "/tmp/sg-lab-ssh-" + std::to_string(getuid());
    mkdir(folder.c_str(), 0700);
    struct stat st {};
    if (lstat(folder.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != getuid() ||
        (st.st_mode & 077) != 0)
      return "/nonexistent";  // someone else's: no shared connection (ssh then connects anew)
    return folder;
  }
  HostSpec host_;
};

}  // namespace

std::string CommandResult::describe() const {
  std::string last = output;
  while (!last.empty() && (last.back() == '\n' || last.back() == '\r')) last.pop_back();
  if (const size_t nl = last.rfind('\n'); nl != std::string::npos) last = last.substr(nl + 1);
  std::string s = "`" + command + "`: ";
  if (timed_out) return s + "timed out" + (last.empty() ? "" : ": " + last);
  if (exit_code < 0) return s + "could not run" + (last.empty() ? "" : ": " + last);
  return s + "exit " + std::to_string(exit_code) + (last.empty() ? "" : ": " + last);
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

CommandResult run_argv(const std::vector<std::string>& argv, double timeout_s,
                       const std::string& input) {
  CommandResult r;
  r.command = join(argv);
  int out[2], in[2];
  if (pipe2(out, O_CLOEXEC) != 0) return r;
  if (pipe2(in, O_CLOEXEC) != 0) {
    close(out[0]), close(out[1]);
    return r;
  }
  const pid_t pid = fork();
  if (pid == 0) exec_child(argv, in[0], out[1]);
  if (pid > 0) setpgid(pid, pid);  // as the child does: no race with a time-out's kill
  close(out[1]);
  close(in[0]);
  if (pid < 0) {
    close(out[0]), close(in[1]);
    return r;
  }
  if (!input.empty()) {
    signal(SIGPIPE, SIG_IGN);
    (void)!write(in[1], input.data(), input.size());
  }
  close(in[1]);
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(timeout_s));
  if (!drain(out[0], r.output, deadline)) {
    r.timed_out = true;
    kill(-pid, SIGKILL);
  }
  close(out[0]);
  r.exit_code = reap(pid);
  return r;
}

std::unique_ptr<HostShell> make_shell(const HostSpec& host, const std::string& local_project) {
  if (host.local()) return std::make_unique<LocalShell>(host, local_project);
  return std::make_unique<SshShell>(host);
}

}  // namespace sg::lab
