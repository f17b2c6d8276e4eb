// sg-grasp's command path with signing required (GraspNode::require_signed_commands): unsigned,
// forged and replayed GRASP_COMMAND are answered RESULT_REFUSED_UNAUTHENTICATED on GRASP_STATUS,
// and a forged sequence 2^63-1 does not stop the operator's next command.

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <numbers>

#include "auth/command_auth.hpp"
#include "grasp/grasp_node.hpp"

namespace sg::grasp {
namespace {

using stereograsp::arm_status_t;
using stereograsp::grasp_command_t;
using stereograsp::grasp_status_t;

constexpr int64_t kT0 = 1'790'000'000'000'000;

/// A clock at kT0 (the signer's counter; nothing here waits).
class FixedClock final : public Clock {
 public:
  double now() override { return static_cast<double>(kT0) * 1e-6; }
  int64_t utime() override { return kT0; }
  bool wait_until(std::unique_lock<std::mutex>&, double, const std::function<bool()>& ready,
                  std::stop_token) override {
    return ready();
  }
  void notify() override {}
  void sleep_until(double) override {}
};

auth::LabKey test_key() {
  std::array<uint8_t, auth::LabKey::kSize> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<uint8_t>(3 * i + 1);
  return auth::LabKey(bytes);
}

/// A node that requires signed commands, with the arm connected at its ready pose.
struct SignedRig {
  auth::LabKey key = test_key();
  GraspNode node{ArmGeometry::a465(), GraspSettings{}, 100, 0.25};
  SignedRig() {
    node.require_signed_commands(key);
    arm_status_t arm{};
    arm.state = arm_status_t::STATE_IDLE;
    const double ready[6] = {0, 0, std::numbers::pi / 2, 0, std::numbers::pi / 2, 0};
    for (int i = 0; i < 6; ++i) arm.joints[i] = ready[i];
    arm.last_executed_sequence = arm.last_rejected_sequence = -1;
    node.on_arm_status(arm, kT0);
  }
};

grasp_command_t home(int64_t sequence) {
  grasp_command_t c{};
  c.utime = kT0;
  c.sequence = sequence;
  c.command = grasp_command_t::COMMAND_HOME;
  c.sender = "sg-grasp-ctl";
  return c;
}

// An unsigned command is refused before any other check, and GRASP_STATUS says so (result 6).
TEST(GraspNodeAuth, UnsignedCommandIsRefusedAndReported) {
  SignedRig rig;
  const CommandRecord& r = rig.node.on_command(home(5), kT0);
  EXPECT_EQ(r.sequence, 5);
  EXPECT_EQ(r.reply.result, CommandResult::kRefusedUnauthenticated);
  EXPECT_EQ(r.reply.reason, "unauthenticated: unsigned command from 'sg-grasp-ctl' (no auth_tag)");
  const GraspNode::Output out = rig.node.poll(kT0);
  ASSERT_TRUE(out.status);
  EXPECT_EQ(out.status->command_sequence, 5);
  EXPECT_EQ(out.status->command_result, grasp_status_t::RESULT_REFUSED_UNAUTHENTICATED);
  EXPECT_EQ(rig.node.command_verifier()->count(auth::Verdict::kUnsigned), 1);
}

// A forged HOME with sequence 2^63-1 is refused and leaves the operator's sequence alone: the
// signed HOME with sequence 5 that follows is accepted; its bytes again at once are a resend,
// answered again; after another command, a replay.
TEST(GraspNodeAuth, ForgedSequenceLocksNoOneOut) {
  SignedRig rig;
  grasp_command_t forged = home(std::numeric_limits<int64_t>::max());
  forged.auth_counter = kT0;
  std::memset(forged.auth_tag, 0x77, sizeof forged.auth_tag);
  EXPECT_EQ(rig.node.on_command(forged, kT0).reply.result,
            CommandResult::kRefusedUnauthenticated);


  FixedClock clock;
  auth::CommandSigner operator_signer(rig.key, "sg-grasp-ctl", clock);
  grasp_command_t real = home(5);
  operator_signer.sign("GRASP_COMMAND", real);
  const CommandRecord& r = rig.node.on_command(real, kT0);
  EXPECT_EQ(r.reply.result, CommandResult::kAccepted) << r.reply.reason;
  EXPECT_EQ(rig.node.machine().status().activity, GraspActivity::kHoming);

  // Its bytes again at once are a resend (sg-grasp-ctl's, when the answer was lost): the same
  // answer, neither verified nor carried out again.
  const CommandRecord& again = rig.node.on_command(real, kT0);
  EXPECT_EQ(again.reply.result, CommandResult::kAccepted);
  EXPECT_EQ(rig.node.command_verifier()->count(auth::Verdict::kAccepted), 1);
  // Signed for another channel, or with another key: refused too.
  grasp_command_t elsewhere = home(6);
  operator_signer.sign("ARM_COMMAND", elsewhere);
  EXPECT_EQ(rig.node.on_command(elsewhere, kT0).reply.result,
            CommandResult::kRefusedUnauthenticated);
  // After another command, the old bytes are a replay.
  const CommandRecord& replay = rig.node.on_command(real, kT0);
  EXPECT_EQ(replay.reply.result, CommandResult::kRefusedUnauthenticated);
  EXPECT_EQ(replay.reply.reason.rfind("unauthenticated: replayed: auth_counter", 0), 0u)
      << replay.reply.reason;
  EXPECT_EQ(rig.node.command_verifier()->count(auth::Verdict::kAccepted), 1);
  EXPECT_EQ(rig.node.command_verifier()->count(auth::Verdict::kBadTag), 2);
  EXPECT_EQ(rig.node.command_verifier()->count(auth::Verdict::kReplayed), 1);
}

// Without require_signed_commands (--insecure-no-key, the in-process trials) an unsigned command
// is judged by the other checks alone.
TEST(GraspNodeAuth, UnsignedAcceptedWhenNotRequired) {
  GraspNode node{ArmGeometry::a465(), GraspSettings{}, 100, 0.25};
  EXPECT_EQ(node.command_verifier(), nullptr);
  EXPECT_NE(node.on_command(home(5), kT0).reply.result, CommandResult::kRefusedUnauthenticated);
}

}  // namespace
}  // namespace sg::grasp
