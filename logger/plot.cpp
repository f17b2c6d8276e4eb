#include "logger/plot.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

namespace sg::logger {
namespace {

constexpr size_t kMaxStderr = 64 * 1024;  // what is kept of gnuplot's stderr

// One line from any text: control characters and non-ASCII bytes become '?'.
std::string printable(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (unsigned char c : text) out.push_back(c >= 0x20 && c < 0x7f ? static_cast<char>(c) : '?');
  return out;
}

// The last non-blank line of `text` (gnuplot ends an error report with the message itself).
std::string last_line(const std::string& text) {
  std::istringstream in(text);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return printable(last);
}

// Reads `fd` until end of file or `deadline`; returns false when the deadline passed first.
bool read_until_eof(int fd, std::chrono::steady_clock::time_point deadline, std::string& out) {
  char buffer[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) return ready == 0 ? false : true;
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;
    if (out.size() < kMaxStderr) out.append(buffer, static_cast<size_t>(n));
  }
}

// In the child after fork(): only async-signal-safe calls, then exec.
[[noreturn]] void exec_child(const char* gnuplot, const char* dir, const char* script,
                             int stderr_fd) {
  const int null_fd = open("/dev/null", O_RDWR);
  if (null_fd < 0 || dup2(null_fd, 0) < 0 || dup2(null_fd, 1) < 0 || dup2(stderr_fd, 2) < 0)
    _exit(126);
  if (chdir(dir) != 0) {
    static const char kMessage[] = "cannot enter the plot directory\n";
    (void)!write(2, kMessage, sizeof kMessage - 1);
    _exit(126);
  }
  execl(gnuplot, gnuplot, script, static_cast<char*>(nullptr));
  static const char kMessage[] = "cannot execute gnuplot\n";
  (void)!write(2, kMessage, sizeof kMessage - 1);
  _exit(127);
}

}  // namespace

std::string Rgb::hex() const {
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", r, g, b);
  return text;
}

int GnuplotData::add_block(const std::string& comment,
                           const std::vector<std::vector<double>>& rows) {
  std::string block = "# " + printable(comment) + "\n";
  int64_t written = 0;
  bool broken = true;  // no blank line before the first row, nor two in a row
  for (const std::vector<double>& row : rows) {
    bool finite = !row.empty();
    for (double v : row) finite = finite && std::isfinite(v);
    if (!finite) {
      if (!broken) block += '\n';
      broken = true;
      continue;
    }
    for (size_t i = 0; i < row.size(); ++i) {
      if (i > 0) block += ' ';
      block += gnuplot_number(row[i]);
    }
    block += '\n';
    broken = false;
    ++written;
  }
  if (written == 0) return -1;
  if (!rows_.empty()) text_ += "\n\n";  // two blank lines: the next block
  text_ += block;
  rows_.push_back(written);
  return static_cast<int>(rows_.size()) - 1;
}

int64_t GnuplotData::rows(int index) const {
  return index >= 0 && index < blocks() ? rows_[static_cast<size_t>(index)] : 0;
}

void GnuplotData::save(const std::string& path) const { write_text_file(path, text_); }

std::string gnuplot_string(const std::string& text, size_t max_chars) {
  std::string body = printable(text);
  if (max_chars < 4) max_chars = 4;
  if (body.size() > max_chars) body = body.substr(0, max_chars - 3) + "...";
  std::string out = "'";
  for (char c : body) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string gnuplot_number(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "1e308" : "-1e308";
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw PlotError(path + ": cannot be written");
}

std::string find_gnuplot(const std::string& program) {
  if (program.find('/') != std::string::npos) {
    if (access(program.c_str(), X_OK) == 0) return program;
    throw GnuplotMissing("gnuplot not found at " + program + " (Debian package gnuplot-nox)");
  }
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/" + program;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  throw GnuplotMissing(program + " not found on PATH (Debian package gnuplot-nox)");
}

void run_gnuplot(const std::string& gnuplot, const std::string& dir, const std::string& script,
                 std::chrono::milliseconds timeout) {
  const std::string where = dir + "/" + script;
  int pipe_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0)
    throw PlotError(where + ": cannot start gnuplot: " + std::strerror(errno));
  const pid_t pid = fork();
  if (pid < 0) {
    close(pipe_fds[0]);
    close(pipe_fds[1]);
    throw PlotError(where + ": cannot start gnuplot: " + std::strerror(errno));
  }
  if (pid == 0) exec_child(gnuplot.c_str(), dir.c_str(), script.c_str(), pipe_fds[1]);
  close(pipe_fds[1]);
  std::string err;
  const bool finished =
      read_until_eof(pipe_fds[0], std::chrono::steady_clock::now() + timeout, err);
  close(pipe_fds[0]);
  if (!finished) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!finished)
    throw PlotError(where + ": gnuplot ran over " + std::to_string(timeout.count()) +
                    " ms and was stopped");
  if (WIFSIGNALED(status))
    throw PlotError(where + ": gnuplot was killed by signal " + std::to_string(WTERMSIG(status)));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw PlotError(where + ": gnuplot failed (exit " + std::to_string(WEXITSTATUS(status)) +
                    "): " + last_line(err));
}

}  // namespace sg::logger
