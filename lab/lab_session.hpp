#pragma once

/// A lab's session: `sg-lab up`, `down`, `status`, `watch`, `logs` and `restart` (issue 18).
///
///     sg::lab::LabSession session(sg::lab::load_lab_file("config/lab.yaml"), project, out);
///     session.up();        // every process on its host, in order, each ready before the next
///     session.status(2.5); // a row per process, the hosts' clocks
///     session.down();      // reverse order; the session log's path and its sg-report summary
///
/// `up` first checks the whole lab — every host answers over ssh, every binary and file is
/// there, the lab is not already up — and refuses naming what is wrong, before it starts
/// anything. It then copies the config and each process's files to the hosts that need them,
/// starts the recorder (lcm-logger, logs/<lab>-<date>-<time>/session.lcmlog on its host) and
/// each process under an `sg-lab supervise` on its host (supervisor.hpp), and waits for each
/// to be ready: a stereograsp program's PROCESS_STATUS in state ready, from its host, or another
/// program still running a second later. A process that does not get ready in time stops the
/// `up`: what was started is stopped, and the process's log is shown.
///
/// The session's record lives in logs/<lab>-<date>-<time>/ of the local checkout, or of
/// `--state DIR` (`sg-lab.state`: a line per process with its host, supervisor pid and log), and
/// <lab>.current there points at it; each host keeps its processes' logs in the same folder of
/// its own checkout.

#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "auth/lab_key.hpp"
#include "lab/lab_file.hpp"

namespace sg::lab {

/// One started process, as sg-lab.state records it.
struct StartedProcess {
  std::string name, host;
  long pid = 0;     ///< the supervisor's, on its host
  std::string log;  ///< relative to the project on its host
};

class LabSession {
 public:
  /// `project`: this checkout's absolute path; `out`: where progress and tables go; `state`: the
  /// folder of the session's record ("" for `project`/logs).
  LabSession(LabFile lab, std::string project, std::ostream& out, std::string state = "");
  ~LabSession();

  /// Starts the lab; throws LabError (after stopping what it started) when it cannot.
  void up();
  /// Stops the lab's processes, the recorder last; prints the session log and its summary.
  /// Returns 0, or 1 when a process had to be killed.
  int down();
  /// Listens `listen_s` to PROCESS_STATUS and prints a row per process and the clocks. Returns
  /// 0 when every process is ready and every clock within tolerance, else 1.
  int status(double listen_s);
  /// Prints, until interrupted, processes joining, stopping beating, coming back or stopping,
  /// supervisors that exited, and clock warnings.
  int watch();
  /// Prints the last `lines` of a process's log.
  int logs(const std::string& name, int lines);
  /// Restarts one process (its supervisor stops and starts it) and waits until it is ready.
  void restart(const std::string& name);
  /// Revokes one process's credentials (docs/security.md): stops it, moves the lab to the next
  /// generation of keys (`<state>/<lab>.generation`), gives every other process new credentials
  /// and restarts it, and deletes the revoked ones from its host. Its old credentials then match
  /// nobody's: whoever holds them is refused ("bad tag") on every channel. Needs the lab key.
  void revoke(const std::string& name);
  /// The lab's key generation (0 until a revoke).
  uint32_t generation() const;

  /// The lab key that up() makes each process's credentials from (lab/lab_credentials.hpp),
  /// and sg-lab's own listener vouches and checks with; none: up() starts every process that
  /// takes a key with --insecure-no-key, and the listener believes everything.
  void use_lab_key(std::optional<auth::LabKey> key) { lab_key_ = std::move(key); }

  /// Name of the session folder in use (after up(), or found by the other commands).
  const std::string& session() const { return session_; }

 private:
  class Listener;  // the bus and the process watch, once needed
  Listener& listener(bool take_part = false);
  void preflight();
  void copy_files();
  /// Makes the processes' credentials (but `skip`'s) from the current generation's key and
  /// copies them to their hosts (one tar stream a host).
  void distribute_credentials(const std::string& skip = "");
  /// The lab key of the current generation (none without a lab key).
  std::optional<auth::LabKey> current_key() const;
  void start(const ProcessSpec& p);
  void wait_ready(const ProcessSpec& p, const StartedProcess& s, double since);
  void stop(const StartedProcess& s, bool& killed);
  void load_state();
  void save_state() const;
  bool alive(const StartedProcess& s);
  /// The names of the started processes whose supervisors run (one ssh call per host).
  std::set<std::string> running();
  std::string log_tail(const StartedProcess& s, int lines);
  std::vector<std::string> argv_of(const ProcessSpec& p) const;
  void report_session();

  LabFile lab_;
  std::string project_;
  std::string state_;  ///< where sg-lab.state and <lab>.current live
  std::ostream& out_;
  std::string session_;  ///< "<lab>-<date>-<time>"
  std::vector<StartedProcess> started_;
  std::unique_ptr<Listener> listener_;
  std::optional<auth::LabKey> lab_key_;
  std::map<std::string, std::string> credentials_;  ///< process -> its credentials on its host
};

/// The recorder as a process of the lab (lcm-logger), named "recorder".
ProcessSpec recorder_process(const LabFile& lab, const std::string& session);

}  // namespace sg::lab
