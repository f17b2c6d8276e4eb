// `sg-lab supervise`, the real binary, over real child processes: restarts by policy with a
// growing back-off, a restart on SIGHUP, and a clean stop on SIGINT that escalates to SIGTERM
// when the process ignores SIGINT.

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <thread>

#include "tests/support/subprocess.hpp"
#include "tests/support/wait.hpp"

namespace sg {
namespace {

using namespace std::chrono_literals;

/// Lines of the supervisor's stderr that contain `what`.
int count(test::Child& supervisor, const std::string& what) {
  const std::string text = test::read_text(supervisor.err_path());
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A process that fails is restarted after 1 s, then 2 s; one that succeeds under on-failure is
// not, and the supervisor exits with its code.
TEST(Supervisor, RestartsAFailureWithBackoff) {
  const std::string dir = test::make_temp_dir();
  // Fails twice (exit 3), then succeeds.
  const std::string script = "n=$(cat " + dir + "/n 2>/dev/null || echo 0); echo $((n+1)) > " +
                             dir + "/n; [ $n -ge 2 ] && exit 0; exit 3";
  test::Child s(
      {test::program("sg-lab"), "supervise", "--name", "flaky", "--", "sh", "-c", script});
  const test::ProcessResult r = s.wait(20s);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("sg-lab: flaky exited with status 3 after"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("restarting in 1.0 s (restart 1)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("restarting in 2.0 s (restart 2)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("exited with status 0 after"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not restarted (restart: on-failure)"), std::string::npos) << r.err;
  EXPECT_EQ(test::read_text(dir + "/n"), "3\n");
}

// restart: never leaves a failed process down and exits with its code.
TEST(Supervisor, NeverPolicyExitsWithTheCode) {
  const test::ProcessResult r = test::run({test::program("sg-lab"), "supervise", "--name", "once",
                                           "--restart", "never", "--", "sh", "-c", "exit 7"},
                                          10s);
  EXPECT_EQ(r.exit_code, 7);
  EXPECT_NE(r.err.find("not restarted (restart: never)"), std::string::npos) << r.err;
}

// SIGHUP restarts the process; SIGINT stops it and the supervisor exits 0.
TEST(Supervisor, HangupRestartsAndInterruptStops) {
  test::Child s({test::program("sg-lab"), "supervise", "--name", "sleeper", "--", "sleep", "600"});
  ASSERT_TRUE(test::eventually([&] { return count(s, "started (pid") == 1; }, 5s, "a start"));
  s.signal(SIGHUP);
  ASSERT_TRUE(test::eventually([&] { return count(s, "started (pid") == 2; }, 10s, "a restart"));
  EXPECT_EQ(count(s, "restarting on request (signal 2 (Interrupt))"), 1);
  s.signal(SIGINT);
  const test::ProcessResult r = s.wait(10s);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.err.find("sg-lab: sleeper stopped (signal 2 (Interrupt))"), std::string::npos)
      << r.err;
}

// --env sets a variable in the process's environment and not in the supervisor's; a pair without
// a name is refused before anything starts.
TEST(Supervisor, EnvironmentIsTheProcesses) {
  const test::ProcessResult r =
      test::run({test::program("sg-lab"), "supervise", "--name", "env", "--restart", "never",
                 "--env", "SG_TEST_SKEW=-0.8 s", "--env", "SG_TEST_EMPTY=", "--", "sh", "-c",
                 "[ \"$SG_TEST_SKEW\" = '-0.8 s' ] && [ -z \"${SG_TEST_EMPTY-unset}\" ] && "
                 "tr '\\0' '\\n' < /proc/$PPID/environ | grep -c '^SG_TEST_SKEW=' ; exit 5"},
                10s);
  EXPECT_EQ(r.exit_code, 5) << r.err;
  EXPECT_EQ(r.out, "0\n") << "the supervisor's own environment does not hold it: " << r.err;
  const test::ProcessResult bad = test::run(
      {test::program("sg-lab"), "supervise", "--name", "env", "--env", "=x", "--", "true"}, 10s);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("not NAME=value: =x"), std::string::npos) << bad.err;
}

// A process that ignores SIGINT gets SIGTERM after the stop time-out.
TEST(Supervisor, StopEscalatesToTerm) {
  test::Child s({test::program("sg-lab"), "supervise", "--name", "stubborn", "--stop-timeout",
                 "0.5", "--", "sh", "-c", "trap '' INT; while :; do sleep 0.1; done"});
  ASSERT_TRUE(test::eventually([&] { return count(s, "started (pid") == 1; }, 5s, "a start"));
  std::this_thread::sleep_for(200ms);  // the shell has set its trap
  const auto t0 = std::chrono::steady_clock::now();
  s.signal(SIGINT);
  const test::ProcessResult r = s.wait(10s);
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.err.find("did not stop on INT within 0.5 s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("stopped (signal 15 (Terminated))"), std::string::npos) << r.err;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 5s);
}

}  // namespace
}  // namespace sg
