#include "sim/c550_emulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "arm_driver/aci.hpp"
#include "arm_driver/rapl.hpp"
#include "arm_driver/units.hpp"

namespace sg::sim {
namespace {

namespace aci = arm::aci;
namespace rapl = arm::rapl;
using Bytes = std::vector<uint8_t>;

Bytes bytes(std::string_view text) { return Bytes(text.begin(), text.end()); }
std::string text(const Bytes& b) { return std::string(b.begin(), b.end()); }
template <size_t N>
Bytes bytes(const std::array<uint8_t, N>& a) {
  return Bytes(a.begin(), a.end());
}

/// A host talking to the emulator byte by byte, at a time the test moves on.
class C550EmulatorTest : public ::testing::Test {
 protected:
  /// Feeds `data` at the current time and returns what is due by then.
  Bytes send(const Bytes& data) {
    for (uint8_t b : data) c550.feed(b, t);
    return c550.take_output(t);
  }
  Bytes send(uint8_t byte) { return send(Bytes{byte}); }

  /// Enquiry and header, both answered; returns what followed the header's ACK.
  Bytes start_transfer(const aci::AciHeader& header) {
    EXPECT_EQ(send(bytes(aci::encode_enquiry(1))), bytes(aci::encode_enquiry_reply(1)));
    const Bytes answer = send(bytes(aci::encode_header(header)));
    EXPECT_FALSE(answer.empty());
    if (answer.empty()) return {};
    EXPECT_EQ(answer.front(), aci::ACK);
    return Bytes(answer.begin() + 1, answer.end());
  }

  /// The 1-byte 0x48 read that opens the session, then the host's ^C (its prompt discarded).
  void open_session() {
    const Bytes block = start_transfer({.slave = 1, .memtype = aci::kMemSession, .length = 1});
    ASSERT_EQ(aci::decode_block(block).data, Bytes{0x01});
    ASSERT_EQ(send(aci::ACK), Bytes{aci::EOT});
    ASSERT_EQ(send(aci::EOT), Bytes{});
    ASSERT_TRUE(c550.in_session());
    t += 0.1;
    ASSERT_EQ(text(send(rapl::CTRL_C)), rapl::kPrompt);
  }

  /// Types `line` checking each echo, sends CR, and returns the reply `wait` seconds later.
  std::string command(const std::string& line, double wait = 0) {
    for (char c : line) {
      const Bytes echo = send(static_cast<uint8_t>(c));
      EXPECT_EQ(echo, Bytes{static_cast<uint8_t>(c)}) << "echo of '" << c << "' in " << line;
    }
    c550.feed(rapl::CR, t);
    t += wait;
    return text(c550.take_output(t));
  }

  /// A reply parsed as the driver parses it.
  static rapl::Reply parse(const std::string& reply) {
    rapl::ReplyReader reader;
    for (char c : reply) reader.feed(static_cast<uint8_t>(c));
    EXPECT_TRUE(reader.complete()) << reply;
    return reader.reply();
  }

  C550Controller controller{arm::ArmGeometry::a465()};
  C550Emulator c550{controller};
  double t = 1.0;
};

// The enquiry 'R', slave+0x20, ENQ is answered 'R', slave+0x20, ACK.
TEST_F(C550EmulatorTest, EnquiryIsAnswered) {
  EXPECT_EQ(send(Bytes{'R', 0x21, aci::ENQ}), (Bytes{'R', 0x21, aci::ACK}));
  EXPECT_EQ(send(Bytes{'x', 'R', 0x21, aci::ENQ}), (Bytes{'R', 0x21, aci::ACK}));
  EXPECT_FALSE(c550.in_session());
}

// An enquiry for another slave gets no answer.
TEST_F(C550EmulatorTest, EnquiryForAnotherSlaveIsIgnored) {
  EXPECT_EQ(send(bytes(aci::encode_enquiry(2))), Bytes{});
  EXPECT_EQ(c550.next_output_time(), std::numeric_limits<double>::infinity());
}

// A header with a bad LRC is NAKed; garbage before a good header is ignored and it is ACKed.
TEST_F(C550EmulatorTest, HeaderWithBadLrcIsNaked) {
  auto header = aci::encode_header({.slave = 1, .write = true, .length = 10});
  header[12] ^= 0x01;
  EXPECT_EQ(send(bytes(header)), Bytes{aci::NAK});
  EXPECT_EQ(c550.take_events().size(), 1u);
  header[12] ^= 0x01;
  Bytes garbage{0x55, 0x00, 0xFE};
  garbage.insert(garbage.end(), header.begin(), header.end());
  EXPECT_EQ(send(garbage), Bytes{aci::ACK});
}

// A header for another slave, or for memory the model refuses, is NAKed.
TEST_F(C550EmulatorTest, HeaderForAnotherSlaveOrReadOnlyMemoryIsNaked) {
  EXPECT_EQ(send(bytes(aci::encode_header({.slave = 3, .length = 1}))), Bytes{aci::NAK});
  EXPECT_EQ(send(bytes(aci::encode_header(
                {.slave = 1, .write = true, .memtype = aci::kMemPointerList, .length = 4}))),
            Bytes{aci::NAK});
  EXPECT_EQ(send(bytes(aci::encode_header({.slave = 1, .memtype = 0x33, .length = 1}))),
            Bytes{aci::NAK});
}

// 129 bytes written then read back through the emulator: two blocks each way, every step ACKed.
TEST_F(C550EmulatorTest, MemoryWriteThenReadRoundTrips129Bytes) {
  Bytes data(129);
  std::iota(data.begin(), data.end(), uint8_t{7});
  const aci::AciHeader write{.slave = 1, .write = true, .offset = 500, .segment = 3, .length = 129};
  EXPECT_EQ(start_transfer(write), Bytes{});
  const auto frames = aci::encode_blocks(data);
  ASSERT_EQ(frames.size(), 2u);
  for (const Bytes& frame : frames) EXPECT_EQ(send(frame), Bytes{aci::ACK});
  EXPECT_EQ(send(aci::EOT), Bytes{});
  EXPECT_EQ(controller.read_memory(aci::kMemSegment, 3, 500, 129), data);

  aci::AciHeader read = write;
  read.write = false;
  Bytes received;
  Bytes frame = start_transfer(read);
  for (int i = 0; i < 2; ++i) {
    const aci::Block block = aci::decode_block(frame);
    EXPECT_EQ(block.last, i == 1);
    received.insert(received.end(), block.data.begin(), block.data.end());
    frame = send(aci::ACK);
  }
  EXPECT_EQ(frame, Bytes{aci::EOT});
  EXPECT_EQ(send(aci::EOT), Bytes{});
  EXPECT_EQ(received, data);
  EXPECT_FALSE(c550.in_session());
}

// A NAK makes the emulator send the same block again; the third NAK abandons the read.
TEST_F(C550EmulatorTest, NakResendsTheSameBlock) {
  const Bytes first = start_transfer({.slave = 1, .length = 200});
  ASSERT_EQ(first.size(), 131u);
  EXPECT_EQ(send(aci::NAK), first);
  EXPECT_EQ(send(aci::NAK), first);
  EXPECT_EQ(send(aci::NAK), Bytes{});
  EXPECT_EQ(send(aci::ACK), Bytes{});  // nothing in progress any more
  EXPECT_EQ(send(bytes(aci::encode_enquiry(1))), bytes(aci::encode_enquiry_reply(1)));
}

// On a host write a block with a bad LRC is NAKed and the good resend ACKed.
TEST_F(C550EmulatorTest, BadBlockOnWriteIsNakedThenAccepted) {
  const Bytes data{1, 2, 3};
  EXPECT_EQ(start_transfer({.slave = 1, .write = true, .length = 3}), Bytes{});
  Bytes frame = aci::encode_blocks(data).front();
  frame.back() ^= 0x40;
  EXPECT_EQ(send(frame), Bytes{aci::NAK});
  frame.back() ^= 0x40;
  EXPECT_EQ(send(frame), Bytes{aci::ACK});
  EXPECT_EQ(send(aci::EOT), Bytes{});
  EXPECT_EQ(controller.read_memory(aci::kMemSegment, 0, 0, 3), data);
}

// The last block sent again (the host lost our ACK) is ACKed again and written once.
TEST_F(C550EmulatorTest, LastBlockResentAfterALostAckIsAckedAgain) {
  const Bytes data{9, 8, 7};
  EXPECT_EQ(start_transfer({.slave = 1, .write = true, .offset = 10, .length = 3}), Bytes{});
  const Bytes frame = aci::encode_blocks(data).front();
  EXPECT_EQ(send(frame), Bytes{aci::ACK});
  EXPECT_EQ(send(frame), Bytes{aci::ACK});
  EXPECT_EQ(send(aci::EOT), Bytes{});
  EXPECT_EQ(controller.read_memory(aci::kMemSegment, 0, 10, 4), (Bytes{9, 8, 7, 0}));
}

// A host that lost our EOT and enquires again is answered; the session is not yet open.
TEST_F(C550EmulatorTest, EnquiryInsteadOfTheEotEchoIsAnswered) {
  start_transfer({.slave = 1, .memtype = aci::kMemSession, .length = 1});
  EXPECT_EQ(send(aci::ACK), Bytes{aci::EOT});
  EXPECT_EQ(send(bytes(aci::encode_enquiry(1))), bytes(aci::encode_enquiry_reply(1)));
  EXPECT_FALSE(c550.in_session());
}

// A header cut short is abandoned after a silence, so a later enquiry is answered.
TEST_F(C550EmulatorTest, PartialHeaderIsAbandonedAfterASilence) {
  const auto header = aci::encode_header({.slave = 1, .length = 1});
  EXPECT_EQ(send(Bytes(header.begin(), header.begin() + 5)), Bytes{});
  t += 0.5;
  EXPECT_EQ(send(bytes(aci::encode_enquiry(1))), bytes(aci::encode_enquiry_reply(1)));
}

// The one-byte 0x48 read answers 0x01 and, once the host echoes EOT, switches to RAPL.
TEST_F(C550EmulatorTest, SessionReadSwitchesToRapl) {
  const Bytes block = start_transfer({.slave = 1, .memtype = aci::kMemSession, .length = 1});
  EXPECT_EQ(block, (Bytes{aci::STX, 0x01, aci::ETX, 0x01}));
  EXPECT_EQ(send(aci::ACK), Bytes{aci::EOT});
  EXPECT_FALSE(c550.in_session());
  EXPECT_EQ(send(aci::EOT), Bytes{});
  EXPECT_TRUE(c550.in_session());
  EXPECT_EQ(text(send(rapl::CTRL_C)), "\r\n>>");
  EXPECT_EQ(command("NOH"), "\x06\r\n>>");
}

// Each printable character is echoed at once on its own; CR is not echoed, ACK comes first.
TEST_F(C550EmulatorTest, EachCharacterIsEchoedAndCrIsNot) {
  open_session();
  for (char c : std::string("speed 50")) {
    EXPECT_EQ(send(static_cast<uint8_t>(c)), Bytes{static_cast<uint8_t>(c)});
  }
  EXPECT_EQ(send(Bytes{rapl::XON, rapl::XOFF, '\n'}), Bytes{});
  EXPECT_EQ(text(send(rapl::CR)), "\x06\r\n>>");
  EXPECT_EQ(controller.speed_percent(), 50);
}

// W2 answers JOINTS in degrees that parse to the controller's joints.
TEST_F(C550EmulatorTest, W2ReplyParsesToTheControllerJoints) {
  open_session();
  const rapl::Reply reply = parse(command("W2"));
  EXPECT_FALSE(reply.error);
  const rapl::JointArray q = rapl::parse_joints(reply);
  const arm::Joints truth = controller.joints(t);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(q[static_cast<size_t>(i)], truth[i], 1e-6);
}

// MA is digested for the interaction delay, then executed and answered; bytes sent meanwhile wait.
TEST_F(C550EmulatorTest, MotionAckArrivesAfterTheInteractionDelay) {
  open_session();
  C550Controller twin(arm::ArmGeometry::a465());  // same seed: the same first delay
  const double delay = twin.interaction_delay();
  const double sent = t;
  EXPECT_EQ(command("MA 10,0,90,0,90,0"), "");           // nothing yet
  EXPECT_FALSE(controller.moving(sent + delay - 1e-6));  // the motion starts after the delay
  EXPECT_NEAR(c550.next_output_time(), sent + delay, 1e-12);
  EXPECT_GE(c550.next_output_time(), sent + 0.72);
  t = sent + 0.5;
  EXPECT_EQ(send(bytes("W2")), Bytes{});  // buffered, not echoed
  EXPECT_EQ(c550.take_output(sent + delay - 1e-9), Bytes{});
  t = sent + delay;
  EXPECT_EQ(text(c550.take_output(t)), "\x06\r\n>>W2");  // the reply, then the held echoes
  EXPECT_TRUE(controller.moving(t));
}

// A refused MA answers after the delay with *** 73 and the prompt, and the arm stays.
TEST_F(C550EmulatorTest, MotionOutsideLimitsIsRefusedAfterTheDelay) {
  open_session();
  EXPECT_EQ(command("MA 0,120,90,0,90,0"), "");
  t += 1.0;
  const rapl::Reply reply = parse(text(c550.take_output(t)));
  ASSERT_TRUE(reply.error);
  EXPECT_TRUE(reply.error->starts_with("*** 73 JOINT LIMIT: joint 2")) << *reply.error;
  EXPECT_FALSE(controller.moving(t));
}

// An unknown command, or bad arguments, gives ACK, a *** 10 line and the prompt.
TEST_F(C550EmulatorTest, UnknownCommandGivesErrorLineAndPrompt) {
  open_session();
  const std::string reply = command("FROB 3");
  EXPECT_EQ(reply, "\x06\r\n*** 10 UNKNOWN COMMAND 'FROB'\r\n>>");
  EXPECT_TRUE(parse(command("MA 1,2,3", 1.0)).error->starts_with("*** 10 MA: expected 6 numbers"));
  EXPECT_TRUE(parse(command("SPEED fast")).error->starts_with("*** 10 SPEED"));
  EXPECT_TRUE(parse(command("SPEED 150")).error->starts_with("*** 10 SPEED 150"));
}

// POINT stores inches and degrees, LLOC gives them back, MOVE takes the arm there.
TEST_F(C550EmulatorTest, PointMoveAndLlocRoundTripInInchesAndDegrees) {
  open_session();
  const Eigen::Vector3d xyz(0.45, 0.10, 0.20), rpy(std::numbers::pi, 0, 0.3);
  EXPECT_EQ(command(rapl::point("grasp", xyz, rpy)), "\x06\r\n>>");
  EXPECT_EQ(command("POINT grasp 17.7165,3.9370,7.8740,180.0000,0.0000,17.1887"), "\x06\r\n>>");
  const rapl::Location location = rapl::parse_location(parse(command("LLOC grasp")));
  EXPECT_EQ(location.name, "grasp");
  EXPECT_NEAR((location.xyz - xyz).norm(), 0.0, 1e-5);
  EXPECT_NEAR((location.rpy - rpy).norm(), 0.0, 1e-5);
  EXPECT_EQ(command("MOVE grasp", 5.0), "\x06\r\n>>");
  const Eigen::Isometry3d tcp = controller.tool_pose(t);
  EXPECT_NEAR((tcp.translation() - xyz).norm(), 0.0, 1e-4);
  EXPECT_TRUE(parse(command("LLOC other")).error->starts_with("*** 10 LLOC"));
  EXPECT_TRUE(parse(command("MOVE other", 1.0)).error->starts_with("*** 10 MOVE"));
}

// ^C drops the typed line and answers the prompt; nothing is executed.
TEST_F(C550EmulatorTest, CtrlCClearsTheLine) {
  open_session();
  EXPECT_EQ(send(bytes("REA")), bytes("REA"));
  EXPECT_EQ(text(send(rapl::CTRL_C)), "\r\n>>");
  EXPECT_EQ(command("NOH"), "\x06\r\n>>");
  EXPECT_EQ(c550.executed_commands(), std::vector<std::string>{"NOH"});
}

// HELP then two ^Z return to ACI mode, where the enquiry is answered again.
TEST_F(C550EmulatorTest, HelpAndTwoCtrlZReturnToAci) {
  open_session();
  EXPECT_EQ(send(Bytes{rapl::CTRL_Z, rapl::CTRL_Z}), Bytes{});  // no HELP: dropped
  EXPECT_TRUE(c550.in_session());
  EXPECT_EQ(command("HELP"), "\x06\r\n>>");
  EXPECT_EQ(send(Bytes{rapl::CTRL_Z, rapl::CTRL_Z}), Bytes{});
  EXPECT_FALSE(c550.in_session());
  EXPECT_EQ(send(bytes(aci::encode_enquiry(1))), bytes(aci::encode_enquiry_reply(1)));
}

// A line longer than kMaxLine is echoed and answered with a *** 10 line.
TEST_F(C550EmulatorTest, OverlongLineIsAnError) {
  open_session();
  const std::string line(rapl::kMaxLine + 1, 'A');
  const rapl::Reply reply = parse(command(line));
  ASSERT_TRUE(reply.error);
  EXPECT_TRUE(reply.error->starts_with("*** 10 LINE TOO LONG: 121")) << *reply.error;
}

// Every command line is recorded once, in order.
TEST_F(C550EmulatorTest, ExecutedCommandsAreRecordedInOrder) {
  open_session();
  command("NOH");
  command("SPEED 30");
  command("READY", 1.0);
  command("W2");
  EXPECT_EQ(c550.executed_commands(), (std::vector<std::string>{"NOH", "SPEED 30", "READY", "W2"}));
  EXPECT_EQ(controller.speed_percent(), 30);
}

// FINISH answers when the motion has ended; ABORT answers at once and stops the arm.
TEST_F(C550EmulatorTest, FinishWaitsForTheMotionAndAbortStops) {
  open_session();
  command("MA 90,0,90,0,90,0", 0.9);  // 1 s: joint 1 at 90 deg/s; the ACK came by 0.84 s
  const double end = controller.settle_time();
  EXPECT_EQ(command("FINISH"), "");
  EXPECT_NEAR(c550.next_output_time(), end, 1e-12);
  t = end;
  EXPECT_EQ(text(c550.take_output(t)), "\x06\r\n>>");
  command("MA 0,0,90,0,90,0", 0.9);
  EXPECT_TRUE(controller.moving(t));
  EXPECT_EQ(command("ABORT"), "\x06\r\n>>");
  EXPECT_FALSE(controller.moving(t));
}

// CLOSE grasps the ball the shell says is at the TCP; OPEN lets it go.
TEST_F(C550EmulatorTest, CloseGraspsTheBallAtTheTcp) {
  open_session();
  c550.set_ball_centre(controller.tool_pose(t).translation());
  EXPECT_EQ(command("CLOSE", 1.0), "\x06\r\n>>");
  EXPECT_TRUE(controller.holding());
  EXPECT_EQ(command("OPEN", 1.0), "\x06\r\n>>");
  EXPECT_FALSE(controller.holding());
}

}  // namespace
}  // namespace sg::sim
