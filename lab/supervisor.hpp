#pragma once

/// The supervisor sg-lab leaves beside each process on its host (`sg-lab supervise`): it starts
/// the process, restarts it by the lab file's policy, restarts it on request, and stops it
/// cleanly. It is the pid sg-lab records and signals, so stopping never needs more than `kill`
/// over ssh, and a process that dies is restarted even while no sg-lab is running.
///
/// Lifecycle (signals to the supervisor):
///
///     start ──▶ running ──exit──▶ (policy: restart after a back-off of 1, 2, 4 ... 30 s,
///                  │                        reset after 60 s of running; or exit with its code)
///                  ├── SIGHUP ──▶ stop the process, start it again at once  (`sg-lab restart`)
///                  └── SIGINT/SIGTERM ──▶ stop the process, exit            (`sg-lab down`)
///
/// Stopping a process is SIGINT, then SIGTERM after `stop_timeout`, then SIGKILL after another:
/// every stereograsp program stops on SIGINT within a second. Each event is one line on the
/// supervisor's stderr (the process's log, which its output shares):
/// `sg-lab: vision exited with status 1 after 0.4 s; restarting in 2 s (restart 2)`.
///
///     sg::lab::SupervisorOptions o;
///     o.name = "vision";
///     o.argv = {"build/bin/sg-vision", "--lcm-url", url};
///     return sg::lab::supervise(o);   // returns when stopped: the process's last exit code

#include <string>
#include <vector>

#include "lab/lab_file.hpp"

namespace sg::lab {

struct SupervisorOptions {
  std::string name;               ///< the lab's name for the process, for messages
  std::vector<std::string> argv;  ///< program and arguments
  /// NAME=value pairs set in the process's environment only (the lab file's process `env`).
  std::vector<std::string> env;
  RestartPolicy restart = RestartPolicy::kOnFailure;
  double stop_timeout = 5;  ///< s after SIGINT before SIGTERM, and after SIGTERM before SIGKILL
  double max_backoff = 30;  ///< s: the restart back-off doubles from 1 s up to this
  double reset_after = 60;  ///< s of running after which the back-off starts again from 1 s
};

/// Runs the supervisor until it is told to stop (SIGINT, SIGTERM) or its process ends for good
/// by the policy; returns the exit code to leave with (the process's, or 0 when stopped).
int supervise(const SupervisorOptions& options);

/// "status 1", "signal 9 (Killed)": how a wait status reads in a message.
std::string describe_exit(int wait_status);

}  // namespace sg::lab
