#pragma once

/// The lab file (issue 18): the one place where a lab's deployment is written down — its hosts,
/// its bus, which process runs where with which flags and files, in which order, when each counts
/// as ready, what happens when one exits, and the session recorder. `sg-lab` reads it.
///
///     sg::lab::LabFile lab = sg::lab::load_lab_file("config/lab.yaml");
///     for (const sg::lab::ProcessSpec& p : lab.processes)   // in start order
///       std::printf("%s on %s: %s\n", p.name.c_str(), p.host.c_str(), p.run[0].c_str());
///
/// A lab file that names an unknown host, repeats a process or host name, gives a process nothing
/// to run, or holds a key that is not one of these is refused with the file, line and column:
/// `config/lab.yaml:31:11: process 'grasp': host 'lab4' is not in hosts (lab1, lab2, lab3)`.
/// Whether binaries exist and hosts answer is checked by `sg-lab up` (lab_session.hpp), which
/// needs the hosts.
///
/// The format, with every key (docs/lab.md):
///
///     lab: sim                        # the name; sessions are logs/<lab>-<date>-<time>/
///     bus: udpm://239.255.76.67:7667?ttl=0   # --lcm-url of every stereograsp process
///     config: config/stereograsp.yaml  # --config of every stereograsp process (copied)
///     hosts:
///       - name: lab1                   # how processes name it; also its `hostname` unless
///         hostname: lab1               #   this says otherwise (PROCESS_STATUS carries it;
///                                      #   a local host: this machine's name)
///         address: 10.0.0.1            # "localhost" (the default): run here, without ssh
///         user: lab                    # ssh user (default: ssh's own choice)
///         port: 22
///         path: /home/lab/stereograsp  # the project's checkout there (default: this one's)
///         ssh_options: [-i, /home/me/.ssh/lab]   # more ssh and scp options
///         env: {TZ: UTC}               # the environment of everything sg-lab runs there
///     processes:                       # started in this order, stopped in the reverse
///       - name: driver
///         host: lab3
///         run: [sg-arm-driver, --device, /tmp/c550, --device-wait, 30]
///         files: [calibration.yaml]    # copied to the host (relative to the project)
///         env: {OMP_NUM_THREADS: 1}    # this process's environment, over its host's
///         ready: status                # status | started: when the next may start
///         restart: on-failure          # on-failure | always | never
///     recorder:                        # lcm-logger, on by default
///       host: lab1
///       exclude: CAMERA_.*             # channels not recorded (lcm-logger --invert-channels)
///     timeouts: {ready: 15, stop: 5}   # s

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "auth/data_auth.hpp"

namespace sg::lab {

/// A lab file that cannot be used; the message names the file, line, column and what is wrong.
class LabError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One machine of the lab.
struct HostSpec {
  std::string name;
  /// What `hostname` prints there (PROCESS_STATUS.host); default: name, or for a local host
  /// this machine's own name (LabSession fills it in: hostname_given is false).
  std::string hostname;
  bool hostname_given = false;
  std::string address = "localhost";
  std::string user;  ///< "" for ssh's default
  int port = 22;
  std::string path;  ///< the project there; "" for this checkout's own path
  std::vector<std::string> ssh_options;
  std::map<std::string, std::string> env;

  /// Runs here, without ssh (address localhost, 127.0.0.1 or ::1).
  bool local() const;
  /// "user@address" or "address", as ssh takes it.
  std::string destination() const;
};

/// When a started process counts as ready, so that the next one may start.
enum class Readiness {
  kStatus,   ///< it published PROCESS_STATUS in state ready (stereograsp daemons)
  kStarted,  ///< it is still running a second after it started (other programs)
};

/// What the supervisor does when the process exits without being asked to.
enum class RestartPolicy { kOnFailure, kAlways, kNever };

/// One process of the lab.
struct ProcessSpec {
  std::string name;
  std::string host;
  std::vector<std::string> run;  ///< program and arguments; an sg-* program from build/bin/
  std::vector<std::string> files;
  /// Its environment, over its host's: only the process gets it, not the supervisor or the
  /// shell commands sg-lab runs on the host.
  std::map<std::string, std::string> env;
  Readiness ready = Readiness::kStatus;
  RestartPolicy restart = RestartPolicy::kOnFailure;
  int line = 0;  ///< where the file defines it, for messages

  /// The program's name (run[0] without a folder).
  std::string program() const;
  /// An sg-* program: it takes --lcm-url and --config, and reports on PROCESS_STATUS.
  bool stereograsp() const;
};

/// The session recorder (lcm-logger).
struct RecorderSpec {
  bool enabled = true;
  std::string host;     ///< default: the first local host, else the first host
  std::string exclude;  ///< channels regex left out ("" records everything)
};

/// A whole lab file.
struct LabFile {
  std::string path;  ///< where it was read from
  std::string lab = "lab";
  std::string bus;     ///< "" for LCM's default
  std::string config;  ///< "" for none
  std::vector<HostSpec> hosts;
  std::vector<ProcessSpec> processes;  ///< in start order
  RecorderSpec recorder;
  /// Who may publish on which channel and who reads it (docs/security.md): the system's table
  /// (auth::default_channel_rights) with the lab file's `rights:` entries over it, an entry
  /// replacing the table's row of its channel or adding one. sg-lab makes credentials from it.
  auth::ChannelRights rights = auth::default_channel_rights();
  double ready_timeout = 15;  ///< s for a process to become ready
  double stop_timeout = 5;    ///< s after SIGINT before SIGTERM, and after SIGTERM before SIGKILL

  const HostSpec& host(const std::string& name) const;
  const ProcessSpec* process(const std::string& name) const;
};

/// Reads and checks a lab file; throws LabError.
LabFile load_lab_file(const std::string& path);
/// Reads and checks lab-file text (`name` stands for the file in messages); throws LabError.
LabFile parse_lab_file(const std::string& text, const std::string& name = "<lab file>");

const char* to_string(Readiness r);
const char* to_string(RestartPolicy r);

}  // namespace sg::lab
