#include "tests/support/wait.hpp"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/bus.hpp"

namespace sg::test {
namespace {

using Clock = std::chrono::steady_clock;

/// Checks `condition` until it holds or `deadline` passes, calling `step(most)` between checks,
/// which waits at most `most` (the poll, or what is left before the deadline when that is less).
bool poll_until(const std::function<bool()>& condition, std::chrono::milliseconds deadline,
                std::chrono::milliseconds poll,
                const std::function<void(std::chrono::milliseconds)>& step) {
  const auto give_up = Clock::now() + deadline;
  while (!condition()) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(give_up - Clock::now());
    if (left <= std::chrono::milliseconds(0)) return condition();
    step(std::min(poll, left));
  }
  return true;
}

::testing::AssertionResult verdict(bool held, std::chrono::milliseconds deadline,
                                   const std::string& what) {
  if (held) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "timed out after " << deadline.count() << " ms waiting for " << what;
}

/// A bound UDP socket of /proc/PID/net/udp: its local port, inode and the bytes in its receive
/// queue.
struct UdpSocket {
  int port = 0;
  std::string inode;
  long receive_queue = 0;
};

std::vector<UdpSocket> udp_sockets(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/net/udp");
  std::vector<UdpSocket> sockets;
  std::string line;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
    fields >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >>
        timeout >> inode;
    const auto colon = local.find(':');
    const auto queue_colon = queues.find(':');  // tx_queue:rx_queue
    if (!fields || colon == std::string::npos || queue_colon == std::string::npos) continue;
    sockets.push_back({std::stoi(local.substr(colon + 1), nullptr, 16), inode,
                       std::stol(queues.substr(queue_colon + 1), nullptr, 16)});
  }
  return sockets;
}

/// The socket inodes process `pid` holds open ("socket:[INODE]" links in /proc/PID/fd).
std::set<std::string> socket_inodes(pid_t pid) {
  std::set<std::string> inodes;
  try {  // a process may close a descriptor, or exit, while this reads
    for (const auto& fd :
         std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/fd")) {
      std::error_code ec;
      const std::string target = std::filesystem::read_symlink(fd.path(), ec).string();
      if (!ec && target.rfind("socket:[", 0) == 0) {
        inodes.insert(target.substr(8, target.size() - 9));
      }
    }
  } catch (const std::filesystem::filesystem_error&) {
  }
  return inodes;
}

/// The UDP sockets `pid` holds, without those this process holds too (inherited ones).
std::vector<UdpSocket> sockets_of(pid_t pid) {
  std::set<std::string> held = socket_inodes(pid);
  if (pid != getpid()) {
    for (const std::string& inode : socket_inodes(getpid())) held.erase(inode);
  }
  std::vector<UdpSocket> own;
  for (const UdpSocket& s : udp_sockets(pid)) {
    if (held.count(s.inode)) own.push_back(s);
  }
  return own;
}

}  // namespace

bool wait_until(const std::function<bool()>& condition, std::chrono::milliseconds deadline,
                std::chrono::milliseconds poll) {
  return poll_until(condition, deadline, poll,
                    [](std::chrono::milliseconds most) { std::this_thread::sleep_for(most); });
}

bool wait_until(Bus& bus, const std::function<bool()>& condition,
                std::chrono::milliseconds deadline, std::chrono::milliseconds poll) {
  return poll_until(condition, deadline, poll,
                    [&bus](std::chrono::milliseconds most) { bus.handle(most); });
}

::testing::AssertionResult eventually(const std::function<bool()>& condition,
                                      std::chrono::milliseconds deadline, const std::string& what,
                                      std::chrono::milliseconds poll) {
  return verdict(wait_until(condition, deadline, poll), deadline, what);
}

::testing::AssertionResult eventually(Bus& bus, const std::function<bool()>& condition,
                                      std::chrono::milliseconds deadline, const std::string& what,
                                      std::chrono::milliseconds poll) {
  return verdict(wait_until(bus, condition, deadline, poll), deadline, what);
}

void handle_for(Bus& bus, std::chrono::milliseconds duration) {
  const auto end = Clock::now() + duration;
  for (auto now = Clock::now(); now < end; now = Clock::now()) {
    bus.handle(std::chrono::ceil<std::chrono::milliseconds>(end - now));
  }
}

bool joined_bus(pid_t pid, int port) {
  bool bound = false, sent = false;
  for (const UdpSocket& s : sockets_of(pid)) (s.port == port ? bound : sent) = true;
  return bound && sent;
}

bool drained_bus(pid_t pid, int port) {
  bool bound = false;
  for (const UdpSocket& s : sockets_of(pid)) {
    if (s.port != port) continue;
    if (s.receive_queue != 0) return false;
    bound = true;
  }
  return bound;
}

namespace {

/// Whether every thread of `pid` is in `state` now (false when it has none, or has exited).
bool all_threads_in(pid_t pid, char state) {
  bool any = false;
  std::error_code ec;
  for (const auto& task :
       std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task", ec)) {
    std::ifstream stat(task.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) return false;
    const auto name_end = line.rfind(')');  // "TID (comm) STATE ..."; comm may hold spaces
    if (name_end == std::string::npos || name_end + 2 >= line.size()) return false;
    if (line[name_end + 2] != state) return false;
    any = true;
  }
  return any && !ec;
}

}  // namespace

bool idle(pid_t pid) {
  if (!all_threads_in(pid, 'S')) return false;
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return all_threads_in(pid, 'S');
}

bool listening_on_bus(pid_t pid, int port) { return joined_bus(pid, port) && idle(pid); }

bool stopped(pid_t pid) { return all_threads_in(pid, 'T'); }

bool handled_bus(pid_t pid, int port) {
  return drained_bus(pid, port) && idle(pid) && drained_bus(pid, port);
}

}  // namespace sg::test
