#pragma once

/// A lab host's shell: run a command there, copy a file there. The local host runs `sh -c`
/// directly; a remote one goes through OpenSSH in batch mode (key-based, never a password
/// prompt), so the same sg-lab code starts processes on a laptop and across a lab.
///
///     std::unique_ptr<sg::lab::HostShell> shell = sg::lab::make_shell(lab.host("lab1"));
///     sg::lab::CommandResult r = shell->run("test -x build/bin/sg-vision", 10.0);
///     if (!r.ok()) throw std::runtime_error(r.describe());
///     shell->copy("calibration.yaml", "calibration.yaml");
///
/// Commands run in the project's folder on the host (HostSpec::path). Every call has a time-out;
/// a command that overruns it is killed (its whole process group) and reported as such.

#include <memory>
#include <string>
#include <vector>

#include "lab/lab_file.hpp"

namespace sg::lab {

/// What a command did.
struct CommandResult {
  int exit_code = -1;  ///< its exit status; 128 + N when killed by signal N; -1: not started
  bool timed_out = false;
  std::string output;   ///< stdout and stderr, interleaved (at most 1 MiB kept)
  std::string command;  ///< what ran, for messages

  bool ok() const { return exit_code == 0 && !timed_out; }
  /// One line: "`test -x ...` on lab1: exit 1: <last line of output>".
  std::string describe() const;
};

/// A host's shell.
class HostShell {
 public:
  virtual ~HostShell() = default;
  /// Runs `command` with `sh -c` in the project's folder on the host.
  virtual CommandResult run(const std::string& command, double timeout_s) = 0;
  /// Copies a local file to `remote_path` (relative to the project's folder there), making its
  /// folder; a local host copies only when the two paths differ.
  virtual CommandResult copy(const std::string& local_path, const std::string& remote_path,
                             double timeout_s) = 0;
  /// Copies files named relative to `local_project` (or absolute) to the same paths relative to
  /// the project's folder on the host (or the same absolute paths), in one call: a tar stream
  /// over one ssh connection; a local host copies only the files whose two paths differ.
  virtual CommandResult copy_all(const std::string& local_project,
                                 const std::vector<std::string>& files, double timeout_s) = 0;
  /// The host as the lab file defines it.
  virtual const HostSpec& host() const = 0;
};

/// The shell of `host`: a local one, or OpenSSH's (ssh -o BatchMode=yes ...).
std::unique_ptr<HostShell> make_shell(const HostSpec& host, const std::string& local_project);

/// `s` in single quotes for sh, its own single quotes escaped.
std::string shell_quote(const std::string& s);

/// Runs `argv` here (no shell), waits up to `timeout_s`, returns what it did; `input` is written
/// to its standard input.
CommandResult run_argv(const std::vector<std::string>& argv, double timeout_s,
                       const std::string& input = "");

}  // namespace sg::lab
