#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace sg::test {

/// What a finished child process left behind.
struct ProcessResult {
  int exit_code = -1;  ///< exit status, or 128 + signal number when killed by a signal
  bool timed_out = false;
  std::string out;  ///< everything it wrote to stdout
  std::string err;  ///< everything it wrote to stderr
};

/// A child process started from argv (no shell), its stdout and stderr captured in files.
/// The destructor kills it if it is still running.
class Child {
 public:
  explicit Child(const std::vector<std::string>& argv);
  ~Child();
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  /// True while the child has not exited (its exit status is kept for wait()).
  bool running();

  /// Sends a signal (SIGINT to stop lcm-logger cleanly, say).
  void signal(int signum);

  /// Waits for the child to exit; after `timeout` it is killed and timed_out is set.
  ProcessResult wait(std::chrono::milliseconds timeout);

  pid_t pid() const { return pid_; }
  /// The file its stderr goes to (readable while it runs).
  const std::string& err_path() const { return err_path_; }

 private:
  pid_t pid_ = -1;
  bool reaped_ = false;
  int status_ = 0;
  std::string out_path_;
  std::string err_path_;
};

/// Runs argv to completion (or `timeout`).
ProcessResult run(const std::vector<std::string>& argv,
                  std::chrono::milliseconds timeout = std::chrono::seconds(60));

/// Path of a program built by this project (build/bin/NAME).
std::string program(const std::string& name);

/// A new empty directory under the system's temporary directory.
std::string make_temp_dir();

/// The whole contents of a file ("" when it cannot be read).
std::string read_text(const std::string& path);

/// Counts the lines of `text` (a last line without a newline counts).
int count_lines(const std::string& text);

}  // namespace sg::test
