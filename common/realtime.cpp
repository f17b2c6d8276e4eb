#include "common/realtime.hpp"

#include <malloc.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace sg {

std::string enter_realtime(int priority) {
  if (priority == 0) return "";
  std::string problems;
  auto note = [&](const std::string& what) {
    problems += (problems.empty() ? "" : "; ") + what + ": " + std::strerror(errno);
  };
  const int lowest = sched_get_priority_min(SCHED_FIFO),
            highest = sched_get_priority_max(SCHED_FIFO);
  if (priority < lowest || priority > highest) {
    return "real-time priority " + std::to_string(priority) + " is outside " +
           std::to_string(lowest) + "-" + std::to_string(highest) + ": not changed";
  }
  sched_param p{};
  p.sched_priority = priority;
  if (sched_setscheduler(0, SCHED_FIFO, &p) != 0) note("SCHED_FIFO " + std::to_string(priority));
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) note("mlockall");
  // Freed memory stays in the heap, and large blocks come from it too (no mmap): a frame's
  // buffers are reused without a system call or a page fault.
  mallopt(M_TRIM_THRESHOLD, -1);
  mallopt(M_MMAP_MAX, 0);
  return problems.empty() ? "" : "real time not entered (" + problems + ")";
}

}  // namespace sg
