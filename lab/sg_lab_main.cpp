// sg-lab: the lab in one command (issue 18). Reads the lab file (config/lab.yaml: hosts, the bus,
// which process runs where, in which order) and starts, watches and stops every process on its
// host over OpenSSH, recording the session with lcm-logger (docs/lab.md).
//
//   sg-lab up                      # every process on its host, in order, each ready before the
//   next sg-lab status                  # host, state, uptime, rates, bad messages, last problem;
//   clocks sg-lab watch                   # processes joining, stopping beating, coming back; clock
//   warnings sg-lab logs vision [-n 50]     # the last lines of a process's log, from its host
//   sg-lab restart vision          # stop it and start it again, wait until ready
//   sg-lab down                    # reverse order; the session log and its sg-report summary
//   sg-lab check                   # read and check the lab file only
//   sg-lab --lab my-lab.yaml up    # another lab file
//
// `sg-lab supervise` is what up leaves beside each process on its host (lab/supervisor.hpp).

#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <regex>

#include "auth/lab_access.hpp"
#include "common/program.hpp"
#include "common/shutdown.hpp"
#include "lab/lab_file.hpp"
#include "lab/lab_session.hpp"
#include "lab/supervisor.hpp"

namespace {

namespace fs = std::filesystem;

/// The checkout this sg-lab was built in (build/bin/sg-lab's grandparent), else the working
/// folder.
std::string project_folder() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec && exe.parent_path().filename() == "bin" &&
      exe.parent_path().parent_path().filename() == "build")
    return exe.parent_path().parent_path().parent_path().string();
  return fs::current_path().string();
}

struct Options {
  std::string lab_file;
  std::string state;
  double listen_s = 2.5;
  int lines = 40;
  std::string name;
  sg::lab::SupervisorOptions supervise;
  std::string restart_policy = "on-failure";
};

CLI::App* add_supervise(CLI::App& app, Options& o) {
  CLI::App* cmd = app.add_subcommand(
      "supervise", "Run one process, restarting it by policy (what `up` starts on each host)");
  cmd->add_option("--name", o.supervise.name, "the lab's name for the process")->required();
  cmd->add_option("--restart", o.restart_policy, "on-failure, always or never")
      ->check(CLI::IsMember({"on-failure", "always", "never"}))
      ->capture_default_str();
  cmd->add_option("--stop-timeout", o.supervise.stop_timeout,
                  "s after SIGINT before SIGTERM, and after SIGTERM before SIGKILL")
      ->check(CLI::Range(0.1, 600.0))
      ->capture_default_str();
  cmd->add_option("--env", o.supervise.env, "NAME=value in the process's environment only")
      ->allow_extra_args(false)  // one pair a --env: the command stays the command
      ->check([](const std::string& e) {
        static const std::regex kPair("[A-Za-z_][A-Za-z0-9_]*=.*");
        return std::regex_match(e, kPair) ? std::string() : "not NAME=value: " + e;
      });
  cmd->add_option("command", o.supervise.argv, "the program and its arguments (after --)")
      ->required();
  return cmd;
}

int supervise(Options& o) {
  o.supervise.restart = o.restart_policy == "always"  ? sg::lab::RestartPolicy::kAlways
                        : o.restart_policy == "never" ? sg::lab::RestartPolicy::kNever
                                                      : sg::lab::RestartPolicy::kOnFailure;
  return sg::lab::supervise(o.supervise);
}

/// The lab key that `up` makes the processes' credentials from (docs/security.md). Without one:
/// for `up`, one line on stderr and kExitNoKey (unless --insecure-no-key); for the other
/// commands, none (they then believe every PROCESS_STATUS they hear).
std::optional<sg::auth::LabKey> load_lab_key(const sg::auth::KeyOptions& o, bool required,
                                             bool& failed) {
  failed = false;
  if (o.insecure) return std::nullopt;
  std::string path;
  try {
    path = o.path.empty() ? sg::auth::default_key_path() : o.path;
    return sg::auth::LabKey::load(path);
  } catch (const sg::auth::LabKeyError& e) {
    if (!required) return std::nullopt;
    std::cerr << "sg-lab: error: " << e.what() << "; sg-lab makes each process's credentials "
              << "from it: make one with `sg-keygen " << path
              << "` on this machine only, give --key PATH, or run with --insecure-no-key\n";
    failed = true;
    return std::nullopt;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Starts, watches and stops a lab's processes on their hosts (docs/lab.md).",
               "sg-lab"};
  app.require_subcommand(1);
  Options o;
  const std::string project = project_folder();
  o.lab_file = (fs::path(project) / "config/lab.yaml").string();
  app.add_option("--lab", o.lab_file, "the lab file")->capture_default_str();
  app.add_option("--state", o.state,
                 "folder of the sessions' records (sg-lab.state, <lab>.current); default: logs/ "
                 "of this checkout");
  sg::auth::KeyOptions key_options;
  sg::auth::add_key_options(app, key_options);
  CLI::App* up = app.add_subcommand("up", "Start every process on its host, in order");
  CLI::App* down = app.add_subcommand("down", "Stop every process, the recorder last; report");
  CLI::App* status = app.add_subcommand("status", "Each process's host, state, rates; the clocks");
  status->add_option("--listen", o.listen_s, "s to listen to PROCESS_STATUS")
      ->check(CLI::Range(1.2, 60.0))
      ->capture_default_str();
  CLI::App* watch = app.add_subcommand("watch", "Print changes until interrupted");
  CLI::App* logs = app.add_subcommand("logs", "The last lines of a process's log");
  logs->add_option("NAME", o.name, "the process")->required();
  logs->add_option("-n,--lines", o.lines, "lines")->check(CLI::Range(1, 100000));
  CLI::App* restart = app.add_subcommand("restart", "Restart one process and wait until ready");
  restart->add_option("NAME", o.name, "the process")->required();
  CLI::App* revoke = app.add_subcommand(
      "revoke", "Stop one process and revoke its credentials: every other one gets new keys");
  revoke->add_option("NAME", o.name, "the process")->required();
  CLI::App* check = app.add_subcommand("check", "Read and check the lab file; start nothing");
  CLI::App* supervise_cmd = add_supervise(app, o);

  return sg::run_program(app, argc, argv, [&] {
    if (*supervise_cmd) return supervise(o);
    const sg::lab::LabFile lab = sg::lab::load_lab_file(o.lab_file);
    if (*check) {
      std::cout << o.lab_file << ": lab '" << lab.lab << "', " << lab.processes.size()
                << " processes on " << lab.hosts.size() << " host(s)\n";
      return 0;
    }
    sg::install_shutdown_handlers();
    sg::lab::LabSession session(lab, project, std::cout, o.state);
    bool no_key = false;
    session.use_lab_key(load_lab_key(key_options, up->parsed() || revoke->parsed(), no_key));
    if (no_key) return sg::auth::kExitNoKey;
    try {
      if (*up) session.up();
      if (*down) return session.down();
      if (*status) return session.status(o.listen_s);
      if (*watch) return session.watch();
      if (*logs) return session.logs(o.name, o.lines);
      if (*restart) session.restart(o.name);
      if (*revoke) session.revoke(o.name);
    } catch (const sg::lab::LabError& e) {  // may end with a log's last lines: keep them
      std::cerr << "sg-lab: error: " << e.what() << "\n";
      return 1;
    }
    return 0;
  });
}
