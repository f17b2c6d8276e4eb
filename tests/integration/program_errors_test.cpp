// Programs meet bad input with one line on stderr and a non-zero exit (DESIGN rule 5).

#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/subprocess.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;

ProcessResult bus_check(const std::vector<std::string>& args) {
  std::vector<std::string> argv = {program("sg-bus-check")};
  argv.insert(argv.end(), args.begin(), args.end());
  return run(argv, 20s);
}

std::string write(const std::string& name, const std::string& text) {
  const std::string path = make_temp_dir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

/// Success when the run failed with exactly one line on stderr, `sg-bus-check: error: ...`,
/// containing `needle`, and printed nothing on stdout.
::testing::AssertionResult one_line_error(const ProcessResult& r, const std::string& needle) {
  if (r.exit_code == 0) return ::testing::AssertionFailure() << "exit code 0";
  if (count_lines(r.err) != 1) return ::testing::AssertionFailure() << "stderr: " << r.err;
  if (r.err.rfind("sg-bus-check: error: ", 0) != 0)
    return ::testing::AssertionFailure() << "no program prefix: " << r.err;
  if (r.err.find(needle) == std::string::npos)
    return ::testing::AssertionFailure() << "'" << needle << "' not in: " << r.err;
  if (!r.out.empty()) return ::testing::AssertionFailure() << "stdout: " << r.out;
  return ::testing::AssertionSuccess();
}

// An unusable LCM URL: LCM's own multi-line complaint becomes one line naming the URL.
TEST(ProgramErrors, BadUrl) {
  EXPECT_TRUE(
      one_line_error(bus_check({"send", "--lcm-url", "bogus://nowhere"}),
                     "cannot open LCM URL 'bogus://nowhere': Error: LCM provider \"bogus\""));
  EXPECT_TRUE(one_line_error(bus_check({"send", "--lcm-url", "udpm://239.255.76.67:7905?ttl=zero"}),
                             "Invalid value for ttl"));
}

// A configuration file that does not exist is named.
TEST(ProgramErrors, MissingConfigFile) {
  EXPECT_TRUE(one_line_error(bus_check({"send", "--config", "/nonexistent/lab.yaml"}),
                             "/nonexistent/lab.yaml: cannot open configuration file"));
}

// A malformed value names the file, the line, the key and the value.
TEST(ProgramErrors, MalformedConfigValue) {
  const std::string path = write("lab.yaml", "bus_check:\n  rate_hz: fast\n");
  EXPECT_TRUE(
      one_line_error(bus_check({"send", "--config", path}),
                     path + ":2:12: key 'bus_check.rate_hz': expected a number, got 'fast'"));
  const std::string negative = write("neg.yaml", "bus_check:\n  count: -5\n");
  EXPECT_TRUE(one_line_error(bus_check({"send", "--config", negative}),
                             negative + ":2:10: key 'bus_check.count': must be in [0, 1000000000], got -5"));
}

// A file that is not YAML at all is refused with its line.
TEST(ProgramErrors, MalformedConfigFile) {
  const std::string path = write("broken.yaml", "bus_check:\n  rate_hz: [1, 2\n");
  EXPECT_TRUE(one_line_error(bus_check({"send", "--config", path}), path + ":"));
}

// Unknown flags are one line too, and --help works and exits 0.
TEST(ProgramErrors, FlagsAndHelp) {
  EXPECT_TRUE(one_line_error(bus_check({"send", "--no-such-flag"}), "--no-such-flag"));
  const ProcessResult help = bus_check({"--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--lcm-url"), std::string::npos);
  EXPECT_NE(help.out.find("--config"), std::string::npos);
}

// A log that is not an LCM log is an error, not a crash.
TEST(ProgramErrors, NotALog) {
  const std::string path = write("notes.txt", "these are not LCM events\n");
  const ProcessResult r = bus_check({"verify-log", path, "--count", "1"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_LT(r.exit_code, 128) << "killed by a signal";
}

}  // namespace
}  // namespace sg::test
