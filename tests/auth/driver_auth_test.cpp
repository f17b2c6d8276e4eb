// sg-arm-driver (with a lab key) against sg-c550-sim on a real pseudo-terminal. Two layers: a
// command nobody vouched for on the bus is refused before any handler (the driver's
// PROCESS_STATUS counts it, ARM_STATUS never hears of it), and the same datagram vouched for
// again is a replay there too; a command vouched for by sg-arm-ctl's credentials but unsigned or
// forged is refused by the command check (ARM_STATUS names it "unauthenticated: ..."). The
// emulator's arm does not move; a signed command is executed; its signature sent again is a
// replay.

#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numbers>
#include <sstream>
#include <thread>

#include "auth/command_auth.hpp"
#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/arm_commands.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"
#include "tests/support/wait.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
using stereograsp::arm_cmd_t;
using stereograsp::arm_status_t;
using stereograsp::sim_arm_state_t;

constexpr int kPort = 7947;

/// How many lines of the emulator's command log start with "MA" (a move reached the controller).
int moves_logged(const std::string& path) {
  int n = 0;
  std::istringstream in(read_text(path));
  for (std::string line; std::getline(in, line);) n += line.find("\tMA") != std::string::npos;
  return n;
}

arm_cmd_t move(int64_t sequence, const std::string& sender) {
  arm_cmd_t c =
      tool_down_move(sequence, 0.45, 0.10, 0.30, std::atan2(0.10, 0.45) + std::numbers::pi);
  c.utime = now_utime();
  c.sender = sender;
  return c;
}

// Unsigned and forged commands move nothing and show in ARM_STATUS; a signed one is executed.
TEST(DriverAuth, RefusesUnsignedAndForgedExecutesSigned) {
  ASSERT_TRUE(multicast_available(kPort));
  const std::string dir = make_temp_dir();
  const std::string key_path = dir + "/lab.key", device = dir + "/c550";
  const std::string log = dir + "/commands.log";
  auth::write_new_key_file(key_path);
  const std::string url = test_url(kPort);
  Bus bus(url);  // the bench: vouches as sg-arm-ctl with the lab key
  const auto bench = vouching_as("sg-arm-ctl", key_path);
  bus.set_guard(bench);
  Bus rogue(url);  // a host of the LAN without credentials
  stereograsp::process_status_t driver_status{};
  bus.subscribe<stereograsp::process_status_t>(
      "PROCESS_STATUS", [&](const stereograsp::process_status_t& s, const ReceiveInfo&) {
        if (s.process == "sg-arm-driver") driver_status = s;
      });
  arm_status_t status{};
  int statuses = 0;
  bus.subscribe<arm_status_t>("ARM_STATUS", [&](const arm_status_t& s, const ReceiveInfo&) {
    status = s;
    ++statuses;
  });
  sim_arm_state_t truth{};
  int truths = 0;
  bus.subscribe<sim_arm_state_t>("SIM_ARM_STATE",
                                 [&](const sim_arm_state_t& s, const ReceiveInfo&) {
                                   truth = s;
                                   ++truths;
                                 });
  Child sim({program("sg-c550-sim"), "--lcm-url", url, "--link", device, "--log-commands", log,
             "--delay-min", "0.3", "--delay-max", "0.4", "--speed", "100"});
  ASSERT_TRUE(eventually([&] { return std::filesystem::exists(device); }, 30s, "the pty"));
  Child driver({program("sg-arm-driver"), "--lcm-url", url, "--device", device, "--key", key_path});
  ASSERT_TRUE(eventually(
      bus, [&] { return statuses > 0 && status.state == arm_status_t::STATE_IDLE && truths > 0; },
      30s, "the driver connected and idle"));
  const sim_arm_state_t at_rest = truth;

  // Not vouched for on the bus: refused before the driver's handler, counted on PROCESS_STATUS.
  rogue.publish("ARM_COMMAND", move(9, "rogue"));
  ASSERT_TRUE(eventually(
      bus, [&] { return unvouched(driver_status, "ARM_COMMAND", "unsigned") >= 1; }, 10s,
      "the unvouched command counted"));
  EXPECT_EQ(status.last_rejected_sequence, -1);  // it never reached the driver
  EXPECT_EQ(status.last_received_sequence, -1);

  // The exact bytes of a vouched datagram, sent twice from the rogue host: the second is a
  // replay on the bus (what lcm-logplayer does with a recorded session).
  std::vector<uint8_t> vouched(static_cast<size_t>(move(8, "rogue").getEncodedSize()));
  const arm_cmd_t eight = move(8, "rogue");
  eight.encode(vouched.data(), 0, static_cast<int>(vouched.size()));
  bench->inner().vouch("ARM_COMMAND", vouched);
  rogue.publish_raw("ARM_COMMAND", vouched.data(), static_cast<int>(vouched.size()));
  ASSERT_TRUE(eventually(
      bus, [&] { return status.last_rejected_sequence == 8; }, 10s,
      "the vouched but unsigned command refused by the command check"));
  rogue.publish_raw("ARM_COMMAND", vouched.data(), static_cast<int>(vouched.size()));
  ASSERT_TRUE(eventually(
      bus, [&] { return unvouched(driver_status, "ARM_COMMAND", "replayed") >= 1; }, 10s,
      "the datagram replayed refused on the bus"));

  // Vouched for, but unsigned: refused by the command check, named, nothing received.
  bus.publish("ARM_COMMAND", move(10, "rogue"));
  ASSERT_TRUE(eventually(
      bus, [&] { return status.last_rejected_sequence == 10; }, 10s,
      "the unsigned command refused"));
  EXPECT_EQ(status.rejection_reason,
            "unauthenticated: unsigned command from 'rogue' (no auth_tag)");
  EXPECT_EQ(status.last_received_sequence, -1);
  EXPECT_EQ(status.commander, "");  // an unauthenticated command takes no lease

  // Forged: issue 15's STOP that locked sg-grasp out, with a random tag.
  arm_cmd_t forged{};
  forged.utime = now_utime();
  forged.sequence = std::numeric_limits<int64_t>::max();
  forged.mode = arm_cmd_t::MODE_STOP;
  forged.speed = 0.5;
  forged.sender = "sg-grasp";
  forged.auth_counter = now_utime();
  std::memset(forged.auth_tag, 0x5a, sizeof forged.auth_tag);
  bus.publish("ARM_COMMAND", forged);
  ASSERT_TRUE(eventually(
      bus, [&] { return status.last_rejected_sequence == std::numeric_limits<int64_t>::max(); },
      10s, "the forged command refused"));
  EXPECT_EQ(status.rejection_reason.rfind("unauthenticated: bad auth_tag on a command from "
                                          "'sg-grasp'",
                                          0),
            0u)
      << status.rejection_reason;
  EXPECT_EQ(status.last_received_sequence, -1);
  EXPECT_EQ(status.last_executed_sequence, -1);
  EXPECT_EQ(moves_logged(log), 0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(truth.tool_position[i], at_rest.tool_position[i], 1e-9) << i;
  }

  // Signed, as sg-grasp, with the lab key: executed, though a forged sg-grasp sequence of
  // 2^63-1 came first; the arm is at the target.
  const auth::LabKey key = auth::command_key(auth::LabKey::load(key_path));
  auth::CommandSigner signer(key, "sg-grasp");
  arm_cmd_t real = move(11, "");
  signer.sign("ARM_COMMAND", real);
  bus.publish("ARM_COMMAND", real);
  ASSERT_TRUE(eventually(
      bus,
      [&] {
        return status.last_executed_sequence == 11 && status.state == arm_status_t::STATE_IDLE;
      },
      20s, "the signed command executed"))
      << status.rejection_reason;
  EXPECT_LT(std::hypot(status.tool_position[0] - 0.45, status.tool_position[1] - 0.10,
                       status.tool_position[2] - 0.30),
            1e-3);
  EXPECT_EQ(moves_logged(log), 1);
  EXPECT_EQ(status.commander, "sg-grasp");  // the signed sender holds the lease

  // The same signed bytes again: a replay, refused before the validator.
  bus.publish("ARM_COMMAND", real);
  ASSERT_TRUE(eventually(
      bus, [&] { return status.last_rejected_sequence == 11; }, 10s, "the replay refused"));
  EXPECT_EQ(status.rejection_reason.rfind("unauthenticated: replayed: auth_counter", 0), 0u)
      << status.rejection_reason;
  EXPECT_EQ(moves_logged(log), 1);

  driver.signal(SIGINT);
  sim.signal(SIGINT);
  EXPECT_EQ(driver.wait(5s).exit_code, 0);
  sim.wait(5s);
}

// Without a key file and without --insecure-no-key the driver exits 2 with one line on how to
// make one; with the flag it starts and warns loudly.
TEST(DriverAuth, NoKeyExitsTwoUnlessInsecure) {
  const std::string dir = make_temp_dir();
  const ProcessResult r = run({program("sg-arm-driver"), "--lcm-url", "memq://", "--device",
                               dir + "/none", "--key", dir + "/absent.key"},
                              10s);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err, "sg-arm-driver: error: lab key " + dir +
                       "/absent.key: no such file; make one with `sg-keygen " + dir +
                       "/absent.key` and copy it to every lab machine (mode 0600), give --key "
                       "PATH, or run with --insecure-no-key\n");
  const ProcessResult insecure = run({program("sg-arm-driver"), "--lcm-url", "memq://", "--device",
                                      dir + "/none", "--insecure-no-key"},
                                     10s);
  EXPECT_NE(insecure.err.find("INSECURE: running without a lab key"), std::string::npos)
      << insecure.err;
  EXPECT_EQ(insecure.exit_code, 1) << insecure.err;  // it got as far as the missing device
}

}  // namespace
}  // namespace sg::test
