// The host side of the C550 line against the real controller model (sim/c550_emulator.hpp) run
// in simulated time: enquiry, the session, ACI memory transfers of every block layout with
// XON/XOFF and control bytes in the data, RAPL-II commands and replies, W2 after a move; and,
// through a scripted byte stream, the faults the emulator does not make: NAKs, bad blocks,
// wrong and missing echoes, a missing reply.

#include "arm_driver/c550_link.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "arm_driver/aci.hpp"
#include "arm_driver/rapl.hpp"
#include "arm_driver/units.hpp"
#include "sim/c550_controller.hpp"
#include "sim/c550_emulator.hpp"
#include "tests/support/arm_commands.hpp"

namespace sg::arm {
namespace {

using Bytes = std::vector<uint8_t>;

Bytes bytes(std::string_view text) { return Bytes(text.begin(), text.end()); }
template <size_t N>
Bytes bytes(const std::array<uint8_t, N>& a) {
  return Bytes(a.begin(), a.end());
}
Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

/// The emulator behind a ByteStream, in simulated time: a write feeds its bytes at the current
/// time; a read returns what is due, moving the clock on to the next output when it comes within
/// the time-out, and otherwise moving it on by the whole time-out and returning nullopt.
class EmulatorStream final : public ByteStream {
 public:
  EmulatorStream(sim::C550Emulator& c550, double t) : c550_(c550), t_(t) {}

  void write(std::span<const uint8_t> data) override {
    for (const uint8_t byte : data) c550_.feed(byte, t_);
    written_.insert(written_.end(), data.begin(), data.end());
  }

  std::optional<uint8_t> read_byte(std::chrono::microseconds timeout) override {
    if (pending_.empty()) {
      const double limit = t_ + 1e-6 * static_cast<double>(timeout.count());
      const double due = c550_.next_output_time();
      if (due > limit) {
        t_ = limit;
        return std::nullopt;
      }
      t_ = std::max(t_, due);
      const Bytes out = c550_.take_output(t_);
      pending_.insert(pending_.end(), out.begin(), out.end());
      if (pending_.empty()) return std::nullopt;
    }
    const uint8_t byte = pending_.front();
    pending_.pop_front();
    return byte;
  }

  void discard_input() override {
    pending_.clear();
    c550_.take_output(t_);
  }

  double now() const { return t_; }
  const Bytes& written() const { return written_; }

 private:
  sim::C550Emulator& c550_;
  double t_;
  std::deque<uint8_t> pending_;
  Bytes written_;
};

/// A stream that answers each write with the next bytes of a script (nothing once the script
/// has run out) and times out at once when it has nothing to read. It records every write.
class ScriptedStream final : public ByteStream {
 public:
  explicit ScriptedStream(std::vector<Bytes> answers) : answers_(std::move(answers)) {}

  void write(std::span<const uint8_t> data) override {
    writes_.emplace_back(data.begin(), data.end());
    if (next_ < answers_.size()) {
      const Bytes& answer = answers_[next_++];
      input_.insert(input_.end(), answer.begin(), answer.end());
    }
  }

  std::optional<uint8_t> read_byte(std::chrono::microseconds /*timeout*/) override {
    if (input_.empty()) return std::nullopt;
    const uint8_t byte = input_.front();
    input_.pop_front();
    return byte;
  }

  void discard_input() override { input_.clear(); }

  const std::vector<Bytes>& writes() const { return writes_; }
  Bytes written() const {
    Bytes all;
    for (const Bytes& w : writes_) all.insert(all.end(), w.begin(), w.end());
    return all;
  }

 private:
  std::vector<Bytes> answers_;
  size_t next_ = 0;
  std::deque<uint8_t> input_;
  std::vector<Bytes> writes_;
};

/// Script answers for a command typed one character at a time: each echoed, then `reply` to CR.
std::vector<Bytes> typed(const std::string& line, const Bytes& reply) {
  std::vector<Bytes> answers;
  for (const char c : line) answers.push_back({static_cast<uint8_t>(c)});
  answers.push_back(reply);
  return answers;
}

const Bytes kPromptBytes = bytes(rapl::kPrompt);
const Bytes kOkReply = concat({{rapl::ACK}, kPromptBytes});

/// `n` bytes rich in what a link could mistake for control: XON, XOFF, the ACI control bytes, an
/// enquiry, NUL, 0xFF, CR, LF, ^Z, interleaved with a counting pattern. Starts with XON, XOFF.
Bytes tricky_data(int n) {
  static constexpr uint8_t kSpecial[] = {0x11, 0x13, 0x00, 0xFF, 0x01, 0x02, 0x03, 0x04, 0x05,
                                         0x06, 0x15, 0x17, 'R',  0x21, 0x05, 0x0D, 0x0A, 0x1A};
  Bytes data(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    data[static_cast<size_t>(i)] =
        i % 3 != 2 ? kSpecial[(i - i / 3) % std::size(kSpecial)] : static_cast<uint8_t>(i * 7 + 3);
  }
  return data;
}

/// Fast settings for tests: no real sleeps.
LinkTiming test_timing() {
  LinkTiming timing;
  timing.session_settle = milliseconds(0);
  return timing;
}

using test::message_of;

testing::AssertionResult contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return testing::AssertionSuccess();
  return testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

class C550LinkTest : public ::testing::Test {
 protected:
  sim::C550Controller controller{ArmGeometry::a465()};
  sim::C550Emulator c550{controller};
  EmulatorStream stream{c550, 1.0};
  C550Link link{stream, 1, test_timing()};
};

// ---- Against the emulator ----

// The enquiry is answered at the first try, and what went out is exactly `'R', 0x21, ENQ`.
TEST_F(C550LinkTest, EnquirySucceeds) {
  link.enquire();
  EXPECT_EQ(stream.written(), (Bytes{'R', 0x21, aci::ENQ}));
  EXPECT_EQ(link.stats().retries, 0);
  EXPECT_EQ(link.stats().bytes_read, 3);
}

// An enquiry for a slave the controller is not is never answered: LinkError after every try.
TEST_F(C550LinkTest, EnquiryForAnotherSlaveFails) {
  LinkTiming timing = test_timing();
  timing.enquiry_tries = 4;
  C550Link other(stream, 2, timing);
  EXPECT_TRUE(contains(message_of<LinkError>([&] { other.enquire(); }),
                       "(slave 2) did not answer 4 enquiries"));
  EXPECT_EQ(other.stats().retries, 3);
}

// open_session enters RAPL-II mode; the controller ran NOH and nothing else.
TEST_F(C550LinkTest, OpenSessionSucceeds) {
  ASSERT_FALSE(c550.in_session());
  link.open_session();
  EXPECT_TRUE(c550.in_session());
  EXPECT_EQ(c550.executed_commands(), std::vector<std::string>{"NOH"});
  EXPECT_EQ(link.stats().retries, 0);
  EXPECT_EQ(link.stats().resyncs, 0);
}

// ACI writes then reads of 1, 127, 128, 129 and 256 bytes (every block layout: one short block,
// one full, full + 1, two full) round trip through the controller's memory, XON/XOFF and control
// bytes in the data included.
TEST_F(C550LinkTest, MemoryRoundTripsEveryLayout) {
  uint16_t offset = 0x0100;
  for (const int n : {1, 127, 128, 129, 256}) {
    SCOPED_TRACE("length " + std::to_string(n));
    const Bytes data = tricky_data(n);
    link.write_memory(aci::kMemSegment, 0x0002, offset, data);
    EXPECT_EQ(controller.read_memory(aci::kMemSegment, 0x0002, offset, n), data);
    EXPECT_EQ(link.read_memory(aci::kMemSegment, 0x0002, offset, n), data);
    offset = static_cast<uint16_t>(offset + 0x200);
  }
  EXPECT_EQ(link.stats().retries, 0);
  EXPECT_FALSE(c550.in_session());
}

// Memory the controller wrote itself reads back through the link, in the right place.
TEST_F(C550LinkTest, ReadsWhatTheControllerHolds) {
  const Bytes data = tricky_data(200);
  controller.write_memory(aci::kMemSegment, 7, 0x1000, data);
  EXPECT_EQ(link.read_memory(aci::kMemSegment, 7, 0x1000, 200), data);
  EXPECT_EQ(link.read_memory(aci::kMemSegment, 7, 0x1000 + 2, 3), Bytes(&data[2], &data[5]));
  EXPECT_EQ(link.read_memory(aci::kMemSegment, 7, 0x0FFF, 1), Bytes{0x00});
}

// The 0x48 session read gives the session byte 0x01 (and opens the session).
TEST_F(C550LinkTest, SessionByteReads) {
  EXPECT_EQ(link.read_memory(aci::kMemSession, 0, 0, 1), Bytes{0x01});
  EXPECT_TRUE(c550.in_session());
}

// A header the controller refuses (past the end of the segment) is NAKed every time: LinkError
// after `retries` tries.
TEST_F(C550LinkTest, RefusedHeaderFailsAfterRetries) {
  EXPECT_TRUE(
      contains(message_of<LinkError>([&] { link.read_memory(aci::kMemSegment, 0, 0xFFFF, 2); }),
               "refused the ACI header 3 times"));
  EXPECT_EQ(link.stats().retries, 2);
}

// Transfers of 0 bytes or more than 32768 have no encoding and are refused before anything is
// sent.
TEST_F(C550LinkTest, UnencodableLengthsSendNothing) {
  EXPECT_THROW(link.write_memory(aci::kMemSegment, 0, 0, {}), aci::AciError);
  EXPECT_THROW(link.read_memory(aci::kMemSegment, 0, 0, 0), aci::AciError);
  EXPECT_THROW(link.read_memory(aci::kMemSegment, 0, 0, aci::kMaxTransfer + 1), aci::AciError);
  EXPECT_TRUE(stream.written().empty());
}

// A `***` reply is a ControllerError carrying the controller's text; the line stays usable.
TEST_F(C550LinkTest, ControllerErrorCarriesItsText) {
  link.open_session();
  EXPECT_EQ(message_of<ControllerError>([&] { link.command("FOO", milliseconds(1000)); }),
            "'FOO': *** 10 UNKNOWN COMMAND 'FOO'");
  EXPECT_TRUE(link.delivered());
  EXPECT_TRUE(link.command("NOH", milliseconds(1000)).lines.empty());
  EXPECT_EQ(link.stats().resyncs, 0);
}

// A motion outside the joint limits is refused after the interaction delay with `*** 73 JOINT
// LIMIT` and the arm stays at READY.
TEST_F(C550LinkTest, MotionOutsideLimitsIsControllerError) {
  link.open_session();
  const double t0 = stream.now();
  const rapl::JointArray q = {
      from_degrees(0), from_degrees(95), from_degrees(90), 0, from_degrees(90), 0};
  EXPECT_TRUE(contains(message_of<ControllerError>(
                           [&] { link.command(rapl::move_joints(q), link.timing().motion_reply); }),
                       "*** 73 JOINT LIMIT"));
  EXPECT_GE(stream.now(), t0 + 0.72);  // the controller digests a motion command first
  EXPECT_TRUE(controller.joints(stream.now()).isApprox(controller.params().ready));
}

// W2 at power-up answers READY: 0, 0, 90, 0, 90, 0 degrees.
TEST_F(C550LinkTest, ReadJointsAtReady) {
  link.open_session();
  const rapl::JointArray q = link.read_joints();
  const std::array<double, 6> expected = {0, 0, 90, 0, 90, 0};
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(to_degrees(q[i]), expected[i], 1e-9) << i;
}

// After MA the controller holds its ACK for the interaction delay (0.72 to 0.84 s of simulated
// time); once FINISH has answered, W2 gives the commanded angles.
TEST_F(C550LinkTest, ReadJointsAfterMove) {
  link.open_session();
  const std::array<double, 6> degrees = {10.5, -20.25, 80, 5, 60.125, -15};
  rapl::JointArray q;
  for (size_t i = 0; i < 6; ++i) q[i] = from_degrees(degrees[i]);
  const double sent = stream.now();
  EXPECT_TRUE(link.command(rapl::move_joints(q), link.timing().motion_reply).lines.empty());
  EXPECT_GE(stream.now() - sent, 0.72);
  EXPECT_LE(stream.now() - sent, 0.84);
  link.command("FINISH", milliseconds(60000));
  EXPECT_FALSE(controller.moving(stream.now()));
  const rapl::JointArray now = link.read_joints();
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(to_degrees(now[i]), degrees[i], 1e-9) << i;
  EXPECT_EQ(c550.executed_commands(),
            (std::vector<std::string>{"NOH", "MA 10.5000,-20.2500,80.0000,5.0000,60.1250,-15.0000",
                                      "FINISH", "W2"}));
}

// A session left open by an earlier driver (the controller still in RAPL-II mode, where an
// enquiry is just text) is closed and opened again.
TEST_F(C550LinkTest, OpenSessionFromCommandMode) {
  link.open_session();
  ASSERT_TRUE(c550.in_session());
  C550Link again(stream, 1, test_timing());
  again.open_session();
  EXPECT_TRUE(c550.in_session());
  EXPECT_EQ(c550.executed_commands(), (std::vector<std::string>{"NOH", "HELP", "NOH"}));
  EXPECT_EQ(again.stats().retries, 0);
  const rapl::JointArray q = again.read_joints();
  EXPECT_NEAR(to_degrees(q[2]), 90, 1e-9);
}

// A driver that died right after sending MA leaves the controller holding the motion's reply
// (every byte buffered until it has gone): open_session still gets through, and MA ran once.
TEST_F(C550LinkTest, OpenSessionWhileMotionReplyHeld) {
  link.open_session();
  const rapl::JointArray q = {from_degrees(20), 0, from_degrees(90), 0, from_degrees(90), 0};
  stream.write(bytes(rapl::move_joints(q) + "\r"));
  C550Link again(stream, 1, test_timing());
  again.open_session();
  EXPECT_TRUE(c550.in_session());
  EXPECT_EQ(c550.executed_commands(),
            (std::vector<std::string>{"NOH", "MA 20.0000,0.0000,90.0000,0.0000,90.0000,0.0000",
                                      "HELP", "NOH"}));
  again.command("FINISH", milliseconds(60000));
  EXPECT_NEAR(to_degrees(again.read_joints()[0]), 20, 1e-9);
}

// A session left with half a command typed is recovered too (^C clears the line).
TEST_F(C550LinkTest, OpenSessionAfterHalfTypedLine) {
  link.open_session();
  stream.write(bytes("MA 1,2"));
  C550Link again(stream, 1, test_timing());
  again.open_session();
  EXPECT_TRUE(c550.in_session());
  EXPECT_EQ(c550.executed_commands(), (std::vector<std::string>{"NOH", "HELP", "NOH"}));
}

// close_session returns the controller to ACI mode, where the enquiry is answered again.
TEST_F(C550LinkTest, CloseSessionReturnsToAci) {
  link.open_session();
  link.close_session();
  EXPECT_FALSE(c550.in_session());
  EXPECT_EQ(c550.executed_commands(), (std::vector<std::string>{"NOH", "HELP"}));
  link.enquire();
  EXPECT_EQ(link.read_memory(aci::kMemSegment, 0, 0, 4), Bytes(4, 0x00));
}

// ---- Faults, scripted ----

// A block NAKed once is sent again and then ACKed: the write succeeds with one retry.
TEST(C550LinkFaultTest, BlockNakThenAck) {
  const Bytes data = {0x11, 0x13, 0x00};
  ScriptedStream line({bytes(aci::encode_enquiry_reply(1)), {aci::ACK}, {aci::NAK}, {aci::ACK}});
  C550Link link(line, 1, test_timing());
  link.write_memory(aci::kMemSegment, 0, 0x40, data);
  EXPECT_EQ(link.stats().retries, 1);
  const Bytes frame = aci::encode_blocks(data).front();
  EXPECT_EQ(line.writes(),
            (std::vector<Bytes>{bytes(aci::encode_enquiry(1)),
                                bytes(aci::encode_header({.slave = 1,
                                                          .write = true,
                                                          .memtype = aci::kMemSegment,
                                                          .offset = 0x40,
                                                          .segment = 0,
                                                          .length = 3})),
                                frame, frame, Bytes{aci::EOT}}));
}

// Every answer to a block is NAK: LinkError after `retries` sends of that block, and no EOT.
TEST(C550LinkFaultTest, BlockAlwaysNakedFails) {
  for (const int retries : {3, 5}) {
    std::vector<Bytes> answers = {bytes(aci::encode_enquiry_reply(1)), {aci::ACK}};
    answers.insert(answers.end(), static_cast<size_t>(retries), Bytes{aci::NAK});
    ScriptedStream line(answers);
    LinkTiming timing = test_timing();
    timing.retries = retries;
    C550Link link(line, 1, timing);
    EXPECT_TRUE(
        contains(message_of<LinkError>([&] {
                   link.write_memory(aci::kMemSegment, 0, 0, {1, 2, 3});
                 }),
                 "ACI block 1 of 1 not acknowledged after " + std::to_string(retries) + " tries"));
    ASSERT_EQ(line.writes().size(), 2u + static_cast<size_t>(retries));
    for (size_t i = 2; i < line.writes().size(); ++i) {
      EXPECT_EQ(line.writes()[i], aci::encode_blocks(Bytes{1, 2, 3}).front()) << i;
    }
    EXPECT_EQ(link.stats().retries, retries - 1);
  }
}

// A header NAKed every time: LinkError after `retries` headers, no block sent.
TEST(C550LinkFaultTest, HeaderAlwaysNakedFails) {
  ScriptedStream line(
      {bytes(aci::encode_enquiry_reply(1)), {aci::NAK}, {aci::NAK}, {aci::NAK}, {aci::ACK}});
  C550Link link(line, 1, test_timing());
  EXPECT_THROW(link.write_memory(aci::kMemSegment, 0, 0, {1}), LinkError);
  ASSERT_EQ(line.writes().size(), 4u);
  EXPECT_EQ(line.writes()[1].size(), static_cast<size_t>(aci::kHeaderSize));
  EXPECT_EQ(line.writes()[3], line.writes()[1]);
}

// A block that arrives with a bad LRC is NAKed; the block sent again is taken: one retry.
TEST(C550LinkFaultTest, BadBlockOnReadIsNakedThenAccepted) {
  const Bytes data = {0x11, 0x13, 0x04, 0x06};
  const Bytes good = aci::encode_blocks(data).front();
  Bytes bad = good;
  bad.back() = static_cast<uint8_t>(bad.back() + 1);
  ScriptedStream line(
      {bytes(aci::encode_enquiry_reply(1)), concat({{aci::ACK}, bad}), good, {aci::EOT}});
  C550Link link(line, 1, test_timing());
  EXPECT_EQ(link.read_memory(aci::kMemSegment, 3, 0x10, 4), data);
  EXPECT_EQ(link.stats().retries, 1);
  ASSERT_EQ(line.writes().size(), 5u);
  EXPECT_EQ(line.writes()[2], Bytes{aci::NAK});
  EXPECT_EQ(line.writes()[3], Bytes{aci::ACK});
  EXPECT_EQ(line.writes()[4], Bytes{aci::EOT});
}

// A read whose last block is not followed by EOT fails.
TEST(C550LinkFaultTest, ReadWithoutEotFails) {
  ScriptedStream line({bytes(aci::encode_enquiry_reply(1)),
                       concat({{aci::ACK}, aci::encode_blocks(Bytes{9}).front()}),
                       {aci::ACK}});
  C550Link link(line, 1, test_timing());
  EXPECT_THROW(link.read_memory(aci::kMemSegment, 0, 0, 1), LinkError);
}

// The enquiry answered only at the third try succeeds with two retries.
TEST(C550LinkFaultTest, EnquiryRetried) {
  ScriptedStream line({{}, {'R', 0x21}, bytes(aci::encode_enquiry_reply(1))});
  C550Link link(line, 1, test_timing());
  link.enquire();
  EXPECT_EQ(link.stats().retries, 2);
  EXPECT_EQ(line.writes().size(), 3u);
}

// XON and XOFF among the echoes and the reply are dropped: the command succeeds with its text.
TEST(C550LinkFaultTest, XonXoffDroppedInCommandMode) {
  ScriptedStream line(
      {{rapl::XOFF, 'W', rapl::XON},
       {'2'},
       concat(
           {{rapl::ACK, rapl::XON}, bytes("\r\nJOINTS 1 2 3 4 5 6"), {rapl::XOFF}, kPromptBytes})});
  C550Link link(line, 1, test_timing());
  const rapl::JointArray q = link.read_joints();
  for (size_t i = 0; i < 6; ++i) EXPECT_NEAR(to_degrees(q[i]), i + 1.0, 1e-9) << i;
  EXPECT_EQ(link.stats().resyncs, 0);
}

// A wrong echo cancels the line: LinkError naming both bytes, not delivered, ^C sent, no CR.
TEST(C550LinkFaultTest, EchoMismatchCancelsLine) {
  ScriptedStream line({{'X'}, kPromptBytes});
  C550Link link(line, 1, test_timing());
  const std::string message =
      message_of<LinkError>([&] { link.command("NOH", milliseconds(1000)); });
  EXPECT_TRUE(contains(message, "echo of 0x4E 'N' came back as 0x58 'X'"));
  EXPECT_FALSE(link.delivered());
  EXPECT_EQ(line.writes(), (std::vector<Bytes>{{'N'}, {rapl::CTRL_C}}));
  EXPECT_EQ(link.stats().resyncs, 1);
}

// A missing echo (time-out) cancels the line the same way.
TEST(C550LinkFaultTest, MissingEchoCancelsLine) {
  ScriptedStream line({{'N'}, {}, kPromptBytes});
  C550Link link(line, 1, test_timing());
  EXPECT_TRUE(
      contains(message_of<LinkError>([&] { link.command("NOH", milliseconds(1000)); }), "no echo"));
  EXPECT_FALSE(link.delivered());
  EXPECT_EQ(line.writes(), (std::vector<Bytes>{{'N'}, {'O'}, {rapl::CTRL_C}}));
}

// No reply after the CR: LinkError with delivered() true (the command may have run), then ^C.
TEST(C550LinkFaultTest, NoReplyAfterCrIsDelivered) {
  std::vector<Bytes> answers = typed("NOH", {});
  answers.push_back(kPromptBytes);
  ScriptedStream line(answers);
  C550Link link(line, 1, test_timing());
  EXPECT_TRUE(contains(message_of<LinkError>([&] { link.command("NOH", milliseconds(1000)); }),
                       "reply to 'NOH'"));
  EXPECT_TRUE(link.delivered());
  EXPECT_EQ(line.written(), (Bytes{'N', 'O', 'H', rapl::CR, rapl::CTRL_C}));
}

// A reply that starts with something other than ACK is a delivered LinkError.
TEST(C550LinkFaultTest, GarbledReplyIsDelivered) {
  ScriptedStream line(typed("NOH", bytes("?\r\n>>")));
  C550Link link(line, 1, test_timing());
  EXPECT_THROW(link.command("NOH", milliseconds(1000)), LinkError);
  EXPECT_TRUE(link.delivered());
}

// A scripted `***` reply is a ControllerError with exactly the controller's text.
TEST(C550LinkFaultTest, ScriptedControllerError) {
  ScriptedStream line(typed(
      "READY", concat({{rapl::ACK}, bytes("\r\n*** 72 LOCATION OUT OF RANGE"), kPromptBytes})));
  C550Link link(line, 1, test_timing());
  EXPECT_EQ(message_of<ControllerError>([&] { link.command("READY", milliseconds(1000)); }),
            "'READY': *** 72 LOCATION OUT OF RANGE");
  EXPECT_TRUE(link.delivered());
}

// Empty and over-long commands are refused before anything is sent.
TEST(C550LinkFaultTest, BadCommandLengthSendsNothing) {
  ScriptedStream line({});
  C550Link link(line, 1, test_timing());
  EXPECT_THROW(link.command("", milliseconds(1000)), LinkError);
  EXPECT_THROW(link.command(std::string(rapl::kMaxLine + 1, 'A'), milliseconds(1000)), LinkError);
  EXPECT_TRUE(line.writes().empty());
  EXPECT_FALSE(link.delivered());
}

}  // namespace
}  // namespace sg::arm
