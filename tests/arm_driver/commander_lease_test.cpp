// The commander lease (arm_driver/commander_lease.hpp) on its own: who holds it after each
// command, what is refused and why, with times given in seconds.

#include "arm_driver/commander_lease.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "stereograsp/arm_cmd_t.hpp"

namespace sg::arm {
namespace {

using Cmd = stereograsp::arm_cmd_t;
const std::string kGrasp = "sg-grasp@lab1:412";
const std::string kCtl = "sg-arm-ctl@lab2:77";

// A free lease goes to the first sender; its commands pass and renew it.
TEST(CommanderLease, FirstSenderTakesAFreeLease) {
  CommanderLease lease(1.6);
  EXPECT_FALSE(lease.held());
  EXPECT_TRUE(std::isinf(lease.deadline()));
  const LeaseDecision d = lease.offer(kGrasp, Cmd::MODE_CARTESIAN, false, 10.0);
  EXPECT_EQ(d.verdict, LeaseVerdict::kCommand);
  EXPECT_TRUE(d.changed);
  EXPECT_EQ(d.taken_from, "");
  EXPECT_EQ(lease.holder(), kGrasp);
  EXPECT_DOUBLE_EQ(lease.deadline(), 11.6);
  const LeaseDecision again = lease.offer(kGrasp, Cmd::MODE_JOINTS, false, 11.0);
  EXPECT_EQ(again.verdict, LeaseVerdict::kCommand);
  EXPECT_FALSE(again.changed);
  EXPECT_DOUBLE_EQ(lease.heard(), 11.0);
}

// Another sender is refused while the holder is heard, with a reason naming the holder and the
// time since it was heard; nothing about the lease changes.
TEST(CommanderLease, AnotherSenderIsRefusedWithTheHolderNamed) {
  CommanderLease lease(1.6);
  lease.offer(kGrasp, Cmd::MODE_CARTESIAN, false, 10.0);
  const LeaseDecision d = lease.offer(kCtl, Cmd::MODE_CARTESIAN, false, 10.2);
  EXPECT_EQ(d.verdict, LeaseVerdict::kRefused);
  EXPECT_EQ(d.reason,
            "arm commanded by 'sg-grasp@lab1:412' (heard 0.2 s ago); sg-arm-ctl --take-over "
            "takes it");
  EXPECT_FALSE(d.changed);
  EXPECT_EQ(lease.holder(), kGrasp);
  EXPECT_DOUBLE_EQ(lease.heard(), 10.0);
}

// take_over hands the lease to the new sender and names whom it was taken from.
TEST(CommanderLease, TakeOverTakesTheLease) {
  CommanderLease lease(1.6);
  lease.offer(kGrasp, Cmd::MODE_CARTESIAN, false, 10.0);
  const LeaseDecision d = lease.offer(kCtl, Cmd::MODE_HOME, true, 10.5);
  EXPECT_EQ(d.verdict, LeaseVerdict::kCommand);
  EXPECT_EQ(d.taken_from, kGrasp);
  EXPECT_TRUE(d.changed);
  EXPECT_EQ(lease.holder(), kCtl);
  EXPECT_EQ(lease.offer(kGrasp, Cmd::MODE_CARTESIAN, false, 10.6).verdict, LeaseVerdict::kRefused);
}

// A holder silent for the timeout loses the lease to the next sender, without take_over.
TEST(CommanderLease, SilentHolderLosesTheLeaseToTheNextSender) {
  CommanderLease lease(1.6);
  lease.offer(kGrasp, Cmd::MODE_CARTESIAN, false, 10.0);
  EXPECT_EQ(lease.offer(kCtl, Cmd::MODE_CARTESIAN, false, 11.5).verdict, LeaseVerdict::kRefused);
  EXPECT_FALSE(lease.expired(11.59));
  EXPECT_TRUE(lease.expired(11.6));
  const LeaseDecision d = lease.offer(kCtl, Cmd::MODE_CARTESIAN, false, 11.7);
  EXPECT_EQ(d.verdict, LeaseVerdict::kCommand);
  EXPECT_EQ(d.taken_from, "");  // not taken over: it had run out
  EXPECT_EQ(lease.holder(), kCtl);
}

// expire() frees the lease only once the timeout has passed, and names who lost it.
TEST(CommanderLease, ExpireFreesTheLeaseAfterTheTimeout) {
  CommanderLease lease(1.6);
  lease.offer(kGrasp, Cmd::MODE_CARTESIAN, false, 10.0);
  EXPECT_EQ(lease.expire(11.0), "");
  EXPECT_EQ(lease.holder(), kGrasp);
  EXPECT_EQ(lease.expire(11.6), kGrasp);
  EXPECT_FALSE(lease.held());
  EXPECT_EQ(lease.expire(20.0), "");
}

// STOP is obeyed from anyone; from a non-holder it neither takes nor renews the lease, from the
// holder it counts as hearing from it.
TEST(CommanderLease, StopFromAnyoneLeavesTheLease) {
  CommanderLease lease(1.6);
  EXPECT_EQ(lease.offer(kCtl, Cmd::MODE_STOP, false, 5.0).verdict, LeaseVerdict::kStop);
  EXPECT_FALSE(lease.held());  // a STOP does not take a free lease
  lease.offer(kGrasp, Cmd::MODE_CARTESIAN, false, 10.0);
  const LeaseDecision d = lease.offer(kCtl, Cmd::MODE_STOP, false, 11.0);
  EXPECT_EQ(d.verdict, LeaseVerdict::kStop);
  EXPECT_FALSE(d.changed);
  EXPECT_EQ(lease.holder(), kGrasp);
  EXPECT_DOUBLE_EQ(lease.heard(), 10.0);
  lease.offer(kGrasp, Cmd::MODE_STOP, false, 11.5);
  EXPECT_DOUBLE_EQ(lease.heard(), 11.5);
}

// MODE_RELEASE from the holder frees the lease; from another sender it is refused and changes
// nothing.
TEST(CommanderLease, ReleaseOnlyByTheHolder) {
  CommanderLease lease(1.6);
  lease.offer(kGrasp, Cmd::MODE_CARTESIAN, false, 10.0);
  const LeaseDecision other = lease.offer(kCtl, Cmd::MODE_RELEASE, false, 10.1);
  EXPECT_EQ(other.verdict, LeaseVerdict::kRefused);
  EXPECT_EQ(lease.holder(), kGrasp);
  EXPECT_DOUBLE_EQ(lease.heard(), 10.0);
  const LeaseDecision mine = lease.offer(kGrasp, Cmd::MODE_RELEASE, false, 10.2);
  EXPECT_EQ(mine.verdict, LeaseVerdict::kReleased);
  EXPECT_TRUE(mine.changed);
  EXPECT_FALSE(lease.held());
  EXPECT_FALSE(lease.offer(kGrasp, Cmd::MODE_RELEASE, false, 10.3).changed);  // already free
}

// A heartbeat renews the holder's lease or takes a free one; a non-holder's heartbeat is refused
// and does not refresh the holder.
TEST(CommanderLease, HeartbeatsRenewOnlyTheHolder) {
  CommanderLease lease(1.6);
  EXPECT_EQ(lease.offer(kGrasp, Cmd::MODE_HEARTBEAT, false, 10.0).verdict, LeaseVerdict::kRenewed);
  EXPECT_EQ(lease.holder(), kGrasp);
  EXPECT_EQ(lease.offer(kGrasp, Cmd::MODE_HEARTBEAT, false, 11.0).verdict, LeaseVerdict::kRenewed);
  EXPECT_DOUBLE_EQ(lease.deadline(), 12.6);
  EXPECT_EQ(lease.offer(kCtl, Cmd::MODE_HEARTBEAT, false, 12.0).verdict, LeaseVerdict::kRefused);
  EXPECT_DOUBLE_EQ(lease.deadline(), 12.6);
  EXPECT_EQ(lease.expire(12.6), kGrasp);
}

// A timeout that is not positive is refused at construction.
TEST(CommanderLease, RefusesANonPositiveTimeout) {
  EXPECT_THROW(CommanderLease(0.0), std::invalid_argument);
  EXPECT_THROW(CommanderLease(std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace sg::arm
