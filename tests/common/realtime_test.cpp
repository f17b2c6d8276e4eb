// sg::enter_realtime: off at 0, refused outside SCHED_FIFO's range, and otherwise either in effect
// (the thread at SCHED_FIFO, memory locked) or unchanged with the reason — in a child process, so
// the test runner keeps its own scheduling.

#include "common/realtime.hpp"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>

namespace sg {
namespace {

// AddressSanitizer makes mlockall a no-op that succeeds (its documented limitation): there, ""
// cannot mean that memory is locked.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kMlockLocks = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kMlockLocks = false;
#else
constexpr bool kMlockLocks = true;
#endif
#else
constexpr bool kMlockLocks = true;
#endif

/// The VmLck line of /proc/self/status in kB (locked memory), -1 when absent.
long locked_kb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmLck:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

// Priority 0 changes nothing and says nothing.
TEST(Realtime, ZeroIsOff) {
  const int before = sched_getscheduler(0);
  EXPECT_EQ(enter_realtime(0), "");
  EXPECT_EQ(sched_getscheduler(0), before);
}

// A priority outside 1-99 is refused with the range, and nothing changes.
TEST(Realtime, OutOfRangeIsRefused) {
  const int before = sched_getscheduler(0);
  const std::string e = enter_realtime(150);
  EXPECT_NE(e.find("outside 1-99"), std::string::npos) << e;
  EXPECT_EQ(sched_getscheduler(0), before);
}

// In a child: "" means SCHED_FIFO at that priority with memory locked (but under ASan); a message
// means the
// scheduler is unchanged (no CAP_SYS_NICE) or memory not locked, as it says.
TEST(Realtime, EitherInEffectOrExplained) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int before = sched_getscheduler(0);
    const std::string e = enter_realtime(10);
    sched_param p{};
    sched_getparam(0, &p);
    bool ok = false;
    if (e.empty()) {
      ok = sched_getscheduler(0) == SCHED_FIFO && p.sched_priority == 10 &&
           (!kMlockLocks || locked_kb() > 0);
    } else {
      const bool fifo = sched_getscheduler(0) == SCHED_FIFO;
      ok = e.find("real time not entered") == 0 &&
           (fifo || (sched_getscheduler(0) == before && e.find("SCHED_FIFO") != std::string::npos));
    }
    _exit(ok ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

}  // namespace
}  // namespace sg
