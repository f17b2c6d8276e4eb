#include "tests/support/subprocess.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "tests/support/wait.hpp"

extern char** environ;

namespace sg::test {

std::string read_text(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

std::string make_temp_dir() {
  const char* base = std::getenv("TMPDIR");
  std::string pattern = std::string(base ? base : "/tmp") + "/sg-test-XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  return pattern;
}

std::string program(const std::string& name) { return std::string(SG_BIN_DIR) + "/" + name; }

int count_lines(const std::string& text) {
  int lines = 0;
  for (char c : text) lines += c == '\n';
  if (!text.empty() && text.back() != '\n') ++lines;
  return lines;
}

Child::Child(const std::vector<std::string>& argv) {
  const std::string dir = make_temp_dir();
  out_path_ = dir + "/stdout";
  err_path_ = dir + "/stderr";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_path_.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path_.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  // Nothing else of the test's: not its bus sockets, which would keep its group membership and
  // make the child look subscribed (joined_bus) before it is.
  posix_spawn_file_actions_addclosefrom_np(&actions, STDERR_FILENO + 1);
  std::vector<char*> args;
  for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  const int status = posix_spawnp(&pid_, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (status != 0) throw std::runtime_error("cannot start " + argv.at(0));
}

Child::~Child() {
  if (!reaped_ && pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

bool Child::running() {
  if (!reaped_ && waitpid(pid_, &status_, WNOHANG) == pid_) reaped_ = true;
  return !reaped_;
}

void Child::signal(int signum) {
  if (!reaped_) kill(pid_, signum);
}

ProcessResult Child::wait(std::chrono::milliseconds timeout) {
  ProcessResult result;
  int status = status_;
  if (!reaped_) {
    reaped_ = wait_until([&] { return waitpid(pid_, &status, WNOHANG) == pid_; }, timeout);
  }
  if (!reaped_) {
    result.timed_out = true;
    kill(pid_, SIGKILL);
    waitpid(pid_, &status, 0);
    reaped_ = true;
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = read_text(out_path_);
  result.err = read_text(err_path_);
  return result;
}

ProcessResult run(const std::vector<std::string>& argv, std::chrono::milliseconds timeout) {
  Child child(argv);
  return child.wait(timeout);
}

}  // namespace sg::test
