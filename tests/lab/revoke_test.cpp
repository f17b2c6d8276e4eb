// A publisher whose credentials sg-lab revoked (lab/lab_session.hpp, LabSession::revoke), with real
// processes that `sg-lab up` started on this host: before the revoke, sg-grasp believes the
// forecasts vouched for with sg-predictor's credentials; `sg-lab revoke predictor` stops it and
// gives every other process new keys; forecasts vouched for with the old credentials (kept by a
// thief) are then refused by sg-grasp as a bad tag, counted on its PROCESS_STATUS, while sg-vision,
// restarted with its new credentials, still believes the cameras.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "auth/credentials_file.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

constexpr int kPort = 7951;

/// A lab of four processes on this host, its host folder `project` (build/ and config/ there).
std::string write_lab(const std::string& dir, const std::string& project) {
  fs::create_directories(project + "/config");
  fs::copy_file(std::string(SG_SOURCE_DIR) + "/config/stereograsp.yaml",
                project + "/config/stereograsp.yaml");
  fs::create_directory_symlink(fs::path(SG_BIN_DIR).parent_path(), project + "/build");
  EXPECT_EQ(run({program("sg-camera-sim"), "--calibration-out", dir + "/cams.yaml", "--frames", "1",
                 "--fast", "--lcm-url", test_url(kPort + 1)})
                .exit_code,
            0);
  std::ofstream(dir + "/lab.yaml")
      << "lab: revoke\n"
      << "bus: " << test_url(kPort) << "\n"
      << "hosts:\n  - {name: local, path: " << project << "}\n"
      << "processes:\n"
      << "  - {name: cameras, host: local, run: [sg-camera-sim, --rate, \"4\"]}\n"
      << "  - {name: vision, host: local, run: [sg-vision, --calibration, " << dir
      << "/cams.yaml]}\n"
      << "  - {name: predictor, host: local, run: [sg-predictor]}\n"
      << "  - {name: grasp, host: local, run: [sg-grasp]}\n"
      << "recorder: off\n";
  return dir + "/lab.yaml";
}

/// The newest PROCESS_STATUS of each program.
struct Statuses {
  explicit Statuses(Bus& bus) {
    bus.subscribe<stereograsp::process_status_t>(
        "PROCESS_STATUS", [this](const auto& s, const auto&) { of[s.process] = s; });
  }
  std::map<std::string, stereograsp::process_status_t> of;
};

stereograsp::trajectory_t forecast() {
  stereograsp::trajectory_t t{};
  t.utime = t.source_utime = now_utime();
  t.period_us = 250'000;
  t.num_points = 1;
  t.position = {{0.45, 0.15, 0.10}};
  t.position_sigma = {{0.001, 0.001, 0.001}};
  t.status = stereograsp::trajectory_t::STATUS_TRACKING;
  return t;
}

/// Publishes 20 forecasts vouched for with `credentials` over 1 s, reading `bus` meanwhile.
void forge(Bus& bus, const std::string& credentials) {
  Bus thief(test_url(kPort));
  thief.set_guard(
      std::make_shared<auth::VouchingPublisher>(auth::load_key_file(credentials, "sg-predictor")));
  for (int i = 0; i < 20; ++i) {
    thief.publish("OBJECT_TRAJECTORY", forecast());
    wait_until(
        bus, [] { return false; }, 50ms);
  }
}

// Revoked credentials are refused by every process the lab restarted; the lab still works.
TEST(Revoke, TheRevokedCredentialsAreRefused) {
  ASSERT_TRUE(multicast_available(kPort));
  const std::string dir = make_temp_dir(), project = dir + "/host";
  const std::string lab = write_lab(dir, project);
  const std::vector<std::string> sg_lab = {program("sg-lab"), "--lab", lab, "--state",
                                           dir + "/state"};
  const auto lab_cmd = [&](std::vector<std::string> args) {
    args.insert(args.begin(), sg_lab.begin(), sg_lab.end());
    return run(args, 120s);
  };
  const ProcessResult up = lab_cmd({"up"});
  ASSERT_EQ(up.exit_code, 0) << up.out << up.err;
  Bus bus(test_url(kPort));
  Statuses statuses(bus);
  fs::path issued;  // the predictor's credentials on its host
  for (const auto& e : fs::recursive_directory_iterator(project + "/.sg-lab"))
    if (e.path().filename() == "predictor.cred") issued = e.path();
  ASSERT_FALSE(issued.empty()) << "no predictor.cred under " << project;
  const std::string stolen = dir + "/stolen.cred";  // as a thief copied them
  fs::copy_file(issued, stolen);

  // Before: sg-grasp believes what the predictor's credentials vouch for.
  forge(bus, stolen);
  ASSERT_TRUE(eventually(
      bus, [&] { return statuses.of.count("sg-grasp") != 0; }, 10s, "sg-grasp"));
  EXPECT_EQ(unvouched(statuses.of["sg-grasp"], "OBJECT_TRAJECTORY", "bad tag"), 0);

  const ProcessResult revoked = lab_cmd({"revoke", "predictor"});
  ASSERT_EQ(revoked.exit_code, 0) << revoked.out << revoked.err;
  EXPECT_NE(revoked.out.find("predictor revoked"), std::string::npos) << revoked.out;
  EXPECT_FALSE(fs::exists(issued)) << "the revoked credentials are still on the host";
  const int64_t after = now_utime();
  forge(bus, stolen);
  const auto refused = [&] {
    return unvouched(statuses.of["sg-grasp"], "OBJECT_TRAJECTORY", "bad tag") >= 20;
  };
  EXPECT_TRUE(eventually(bus, refused, 10s, "sg-grasp to refuse the revoked forecasts"))
      << unvouched(statuses.of["sg-grasp"], "OBJECT_TRAJECTORY", "bad tag");
  // The restarted sg-vision believes the restarted cameras: positions keep coming.
  int64_t positions = 0;
  bus.subscribe<stereograsp::point3_t>(
      "OBJECT_POSITION", [&](const auto& p, const auto&) { positions += p.utime > after; });
  EXPECT_TRUE(eventually(
      bus, [&] { return positions >= 3; }, 15s, "positions after the revoke"));
  EXPECT_EQ(lab_cmd({"down"}).exit_code, 0);
}

}  // namespace
}  // namespace sg::test
