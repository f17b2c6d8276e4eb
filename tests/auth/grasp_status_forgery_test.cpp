// sg-grasp-ctl believes GRASP_STATUS only from sg-grasp: with no sg-grasp on the bus, a host that
// answers each GRASP_COMMAND with a GRASP_STATUS saying "accepted, tracking" for its sequence
// makes `sg-grasp-ctl track` exit 0 only when that host vouches as sg-grasp; a host without
// credentials, or one vouching as sg-predictor, leaves it without an answer (exit 1, one line),
// each refusal logged with its verdict.

#include <gtest/gtest.h>

#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/message_types.hpp"
#include "tests/integration/multicast_guard.hpp"
#include "tests/support/subprocess.hpp"
#include "tests/support/vouching.hpp"

namespace sg::test {
namespace {

using namespace std::chrono_literals;
using stereograsp::grasp_command_t;
using stereograsp::grasp_status_t;

constexpr int kPort = 7952;

/// Runs `sg-grasp-ctl track` while `answerer` answers every GRASP_COMMAND as sg-grasp would.
ProcessResult track_answered_by(Bus& answerer) {
  std::vector<grasp_command_t> heard;
  answerer.subscribe<grasp_command_t>("GRASP_COMMAND",
                                      [&](const auto& c, const auto&) { heard.push_back(c); });
  Child ctl({program("sg-grasp-ctl"), "--lcm-url", test_url(kPort), "--timeout", "3", "track"});
  while (ctl.running()) {
    answerer.handle(20ms);
    for (const grasp_command_t& c : heard) {
      grasp_status_t s{};
      s.utime = now_utime();
      s.command_sequence = c.sequence;
      s.command_result = grasp_status_t::RESULT_ACCEPTED;
      s.activity = grasp_status_t::ACTIVITY_TRACKING;
      answerer.publish("GRASP_STATUS", s);
    }
    heard.clear();
  }
  return ctl.wait(5s);
}

// Only sg-grasp's answer is believed.
TEST(GraspStatusForgery, OnlySgGraspsAnswerIsBelieved) {
  ASSERT_TRUE(multicast_available(kPort));
  {
    Bus stranger(test_url(kPort));
    const ProcessResult r = track_answered_by(stranger);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("GRASP_STATUS: refused, not vouched for (unsigned)"), std::string::npos)
        << r.err;
  }
  {
    Bus predictor(test_url(kPort));
    predictor.set_guard(vouching_as("sg-predictor"));
    const ProcessResult r = track_answered_by(predictor);
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("GRASP_STATUS: refused, not vouched for (not allowed)"), std::string::npos)
        << r.err;
  }
  {
    Bus grasp(test_url(kPort));
    grasp.set_guard(vouching_as("sg-grasp"));
    const ProcessResult r = track_answered_by(grasp);
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  }
}

}  // namespace
}  // namespace sg::test
