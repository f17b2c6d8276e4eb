// The lab file: the committed default reads, and every kind of mistake is refused with the file,
// line and column and the thing it names.

#include "lab/lab_file.hpp"

#include <gtest/gtest.h>

namespace sg::lab {
namespace {

/// A two-host lab; `extra` is appended under processes.
std::string lab_text(const std::string& extra = "") {
  return "lab: t\n"
         "bus: udpm://239.255.76.67:7681?ttl=1\n"
         "hosts:\n"
         "  - {name: eyes, address: 10.0.0.11, user: lab, port: 2222, path: /srv/sg}\n"
         "  - name: here\n"
         "processes:\n"
         "  - {name: vision, host: eyes, run: [sg-vision, --calibration, c.yaml], files: "
         "[c.yaml]}\n"
         "  - {name: logger2, host: here, run: [lcm-logger, x.lcmlog], restart: never}\n" +
         extra;
}

/// The message of the LabError that parsing `text` throws ("" if none).
std::string refusal(const std::string& text) {
  try {
    parse_lab_file(text, "lab.yaml");
  } catch (const LabError& e) {
    return e.what();
  }
  return "";
}

// The committed config/lab.yaml is the whole simulated loop on this host, recorded.
TEST(LabFile, DefaultLabReads) {
  const LabFile lab = load_lab_file(std::string(SG_SOURCE_DIR) + "/config/lab.yaml");
  EXPECT_EQ(lab.lab, "sim");
  ASSERT_EQ(lab.hosts.size(), 1u);
  EXPECT_TRUE(lab.hosts[0].local());
  ASSERT_EQ(lab.processes.size(), 6u);
  EXPECT_EQ(lab.processes[0].program(), "sg-c550-sim");
  EXPECT_EQ(lab.processes[1].program(), "sg-arm-driver");
  EXPECT_TRUE(lab.recorder.enabled);
  EXPECT_EQ(lab.recorder.host, "local");
  EXPECT_EQ(lab.recorder.exclude, "CAMERA_.*");
}

// Hosts, processes, defaults: readiness by status for sg-* programs, started for others.
TEST(LabFile, FieldsAndDefaults) {
  const LabFile lab = parse_lab_file(lab_text());
  const HostSpec& eyes = lab.host("eyes");
  EXPECT_FALSE(eyes.local());
  EXPECT_EQ(eyes.destination(), "lab@10.0.0.11");
  EXPECT_EQ(eyes.port, 2222);
  EXPECT_EQ(eyes.hostname, "eyes");
  EXPECT_TRUE(lab.host("here").local());
  EXPECT_EQ(lab.processes[0].ready, Readiness::kStatus);
  EXPECT_EQ(lab.processes[0].restart, RestartPolicy::kOnFailure);
  EXPECT_EQ(lab.processes[1].ready, Readiness::kStarted);
  EXPECT_EQ(lab.processes[1].restart, RestartPolicy::kNever);
  EXPECT_EQ(lab.recorder.host, "here") << "the first local host records by default";
  EXPECT_DOUBLE_EQ(lab.ready_timeout, 15);
}

// A process on a host the file does not define is refused, naming the hosts there are.
TEST(LabFile, UnknownHostIsRefused) {
  EXPECT_EQ(refusal(lab_text("  - {name: grasp, host: brain, run: [sg-grasp]}\n")),
            "lab.yaml:9:5: process 'grasp': host 'brain' is not in hosts (eyes, here)");
}

// Two processes of one name are refused.
TEST(LabFile, DuplicateProcessIsRefused) {
  EXPECT_EQ(refusal(lab_text("  - {name: vision, host: here, run: [sg-vision]}\n")),
            "lab.yaml:9:5: process 'vision' is defined twice (names must be unique)");
}

// A misspelt key is refused with the key it was probably meant to be.
TEST(LabFile, UnknownKeyIsRefusedWithTheNearest) {
  EXPECT_EQ(refusal(lab_text("  - {name: g, host: here, run: [sg-grasp], restrat: never}\n")),
            "lab.yaml:9:44: process 'g': unknown key 'restrat' (did you mean 'restart'?)");
}

// A process with nothing to run, a bad policy, a bad port, a bad name: each refused.
TEST(LabFile, BadValuesAreRefused) {
  EXPECT_NE(refusal(lab_text("  - {name: g, host: here}\n")).find("'run' must give the program"),
            std::string::npos);
  EXPECT_NE(refusal(lab_text("  - {name: g, host: here, run: [x], restart: sometimes}\n"))
                .find("'restart' must be one of on-failure, always, never, got 'sometimes'"),
            std::string::npos);
  EXPECT_NE(refusal("lab: t\nhosts: [{name: a, port: 70000}]\nprocesses: [{name: p, host: a, "
                    "run: [x]}]\n")
                .find("'port' must be in [1, 65535]"),
            std::string::npos);
  EXPECT_NE(refusal(lab_text("  - {name: ../etc, host: here, run: [x]}\n"))
                .find("'name' must be a plain name"),
            std::string::npos);
  EXPECT_NE(refusal("lab: [").find("lab.yaml:1:"), std::string::npos);
  // A list where text belongs (an env value, a key): refused with the place, not yaml-cpp's throw.
  EXPECT_EQ(refusal("lab: t\nhosts: [{name: a, env: {K: [1, 2]}}]\nprocesses: [{name: p, host: "
                    "a, run: [x]}]\n")
                .rfind("lab.yaml:2:", 0),
            0u);
  EXPECT_EQ(refusal(lab_text("  - {[a]: 1}\n")).rfind("lab.yaml:", 0), 0u);
  EXPECT_NE(refusal("lab: t\nhosts: []\nprocesses: []\n").find("at least one host"),
            std::string::npos);
}

// A process's env is its own, beside its host's; a variable name a shell would not take (which
// sg-lab's commands would otherwise splice into a shell line) is refused, naming it.
TEST(LabFile, ProcessEnvironment) {
  const LabFile lab =
      parse_lab_file(lab_text("  - {name: g, host: here, run: [sg-grasp], env: {FAKETIME: "
                              "\"-0.8\", OMP_NUM_THREADS: 1}}\n"));
  const ProcessSpec& g = *lab.process("g");
  EXPECT_EQ(g.env.size(), 2u);
  EXPECT_EQ(g.env.at("FAKETIME"), "-0.8");
  EXPECT_EQ(g.env.at("OMP_NUM_THREADS"), "1");
  EXPECT_TRUE(lab.process("vision")->env.empty());
  EXPECT_NE(refusal(lab_text("  - {name: g, host: here, run: [x], env: {\"A; rm -r /\": 1}}\n"))
                .find("process 'g': 'env' names a variable 'A; rm -r /'"),
            std::string::npos);
  EXPECT_NE(refusal("lab: t\nhosts: [{name: a, env: {1X: y}}]\nprocesses: [{name: p, host: a, "
                    "run: [x]}]\n")
                .find("host 'a': 'env' names a variable '1X'"),
            std::string::npos);
  EXPECT_NE(refusal(lab_text("  - {name: g, host: here, run: [x], env: [A]}\n"))
                .find("'env' must be a mapping"),
            std::string::npos);
}

// `recorder: off` records nothing; a recorder on an unknown host is refused.
TEST(LabFile, Recorder) {
  EXPECT_FALSE(parse_lab_file(lab_text() + "recorder: off\n").recorder.enabled);
  EXPECT_NE(refusal(lab_text() + "recorder: {host: nowhere}\n")
                .find("recorder: host 'nowhere' is not in hosts (eyes, here)"),
            std::string::npos);
}

}  // namespace
}  // namespace sg::lab
