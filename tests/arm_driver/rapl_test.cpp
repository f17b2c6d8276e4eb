// RAPL-II as text: the commands the driver sends (SPEED, MA, POINT, MOVE, LLOC), the byte-by-byte
// reply reader (ACK, text, CR LF ">>"), the W2 and LLOC reply parsers and the controller-side
// helpers. Expected strings are derived by hand from /work/shared/reference/c550-aci.md.

#include "arm_driver/rapl.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

namespace sg::arm::rapl {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

/// Feeds every byte of `bytes` to `reader`.
void feed_all(ReplyReader& reader, std::string_view bytes) {
  for (char c : bytes) reader.feed(static_cast<uint8_t>(c));
}

/// A reply holding the given lines.
Reply reply_of(std::vector<std::string> lines) {
  Reply reply;
  reply.lines = std::move(lines);
  return reply;
}

// ---- Commands ----

// SPEED takes a percentage 1..100 and refuses anything else.
TEST(RaplCommands, Speed) {
  EXPECT_EQ(speed(1), "SPEED 1");
  EXPECT_EQ(speed(50), "SPEED 50");
  EXPECT_EQ(speed(100), "SPEED 100");
  EXPECT_THROW(speed(0), RaplError);
  EXPECT_THROW(speed(101), RaplError);
  EXPECT_THROW(speed(-5), RaplError);
}

// MA lists the six joints in degrees with four decimals, separated by commas.
TEST(RaplCommands, MoveJointsDegreesFourDecimals) {
  const JointArray q{0.0, kPi / 2, -kPi / 4, kPi, kPi / 6, -kPi / 3};
  EXPECT_EQ(move_joints(q), "MA 0.0000,90.0000,-45.0000,180.0000,30.0000,-60.0000");
}

// MA rounds to four decimals (12.34567 deg -> 12.3457, -179.99994 deg -> -179.9999).
TEST(RaplCommands, MoveJointsRounding) {
  const JointArray q{12.34567 * kDeg, 1.5 * kDeg,    -179.99994 * kDeg,
                     0.25 * kDeg,     -7.125 * kDeg, 100.00001 * kDeg};
  EXPECT_EQ(move_joints(q), "MA 12.3457,1.5000,-179.9999,0.2500,-7.1250,100.0000");
}

// A tiny negative angle prints as 0.0000, never "-0.0000" (-1e-9 rad rounds to zero).
TEST(RaplCommands, NegativeZeroPrintsAsZero) {
  const JointArray q{-1e-9, -0.0, 0.0, -0.00004 * kDeg, 0.00004 * kDeg, -0.00006 * kDeg};
  EXPECT_EQ(move_joints(q), "MA 0.0000,0.0000,0.0000,0.0000,0.0000,-0.0001");
}

// MA refuses joints that are NaN or infinite.
TEST(RaplCommands, MoveJointsRefusesNonFinite) {
  JointArray q{};
  q[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(move_joints(q), RaplError);
  q[3] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(move_joints(q), RaplError);
  q[3] = 0;
  q[0] = -std::numeric_limits<double>::infinity();
  EXPECT_THROW(move_joints(q), RaplError);
}

// POINT gives the position in inches and the orientation in degrees, %.4f, comma separated.
TEST(RaplCommands, PointInchesAndDegrees) {
  // 0.0254 m = 1 in, 0.254 m = 10 in, -0.0127 m = -0.5 in; pi = 180 deg, -pi/2 = -90 deg.
  EXPECT_EQ(point("P1", {0.0254, 0.254, -0.0127}, {kPi, 0.0, -kPi / 2}),
            "POINT P1 1.0000,10.0000,-0.5000,180.0000,0.0000,-90.0000");
  // 0.45 m / 0.0254 = 17.716535... in; 0.3048 m = 12 in; 1 rad = 57.29578 deg.
  EXPECT_EQ(point("HOVER", {0.45, 0.3048, 0.0}, {1.0, kPi / 4, 0.0}),
            "POINT HOVER 17.7165,12.0000,0.0000,57.2958,45.0000,0.0000");
}

// MOVE and LLOC name the location.
TEST(RaplCommands, MoveAndLloc) {
  EXPECT_EQ(move("P1"), "MOVE P1");
  EXPECT_EQ(lloc("P1"), "LLOC P1");
  EXPECT_EQ(move("GRASP2"), "MOVE GRASP2");
  EXPECT_EQ(lloc("GRASP2"), "LLOC GRASP2");
}

// ---- ReplyReader ----

// A reply with no text: ACK then CR LF ">>", complete only at the last '>'.
TEST(RaplReplyReader, PlainAck) {
  ReplyReader reader;
  EXPECT_FALSE(reader.acknowledged());
  EXPECT_FALSE(reader.complete());
  reader.feed(0x06);
  EXPECT_TRUE(reader.acknowledged());
  EXPECT_FALSE(reader.complete());
  reader.feed('\r');
  reader.feed('\n');
  reader.feed('>');
  EXPECT_FALSE(reader.complete());
  reader.feed('>');
  EXPECT_TRUE(reader.complete());
  const Reply reply = reader.reply();
  EXPECT_TRUE(reply.lines.empty());
  EXPECT_FALSE(reply.error.has_value());
}

// Text between the ACK and the prompt comes back as its non-empty lines.
TEST(RaplReplyReader, TextLines) {
  ReplyReader reader;
  feed_all(reader, "\x06\r\nJOINTS 10.0000 -20.0000 30.5000 0.0000 90.0000 -180.0000\r\n>>");
  ASSERT_TRUE(reader.complete());
  const Reply reply = reader.reply();
  ASSERT_EQ(reply.lines.size(), 1u);
  EXPECT_EQ(reply.lines[0], "JOINTS 10.0000 -20.0000 30.5000 0.0000 90.0000 -180.0000");
  EXPECT_FALSE(reply.error.has_value());

  ReplyReader two;
  feed_all(two,
           "\x06"
           "FIRST LINE\r\n\r\nSECOND\r\n>>");
  ASSERT_TRUE(two.complete());
  EXPECT_EQ(two.reply().lines, (std::vector<std::string>{"FIRST LINE", "SECOND"}));
}

// A line starting with "***" is the controller's error (the first one if there are several).
TEST(RaplReplyReader, ErrorLine) {
  ReplyReader reader;
  feed_all(reader, "\x06\r\n*** 72 LOCATION OUT OF RANGE\r\n*** 2 SECOND\r\n>>");
  ASSERT_TRUE(reader.complete());
  const Reply reply = reader.reply();
  ASSERT_TRUE(reply.error.has_value());
  EXPECT_EQ(*reply.error, "*** 72 LOCATION OUT OF RANGE");
  EXPECT_EQ(reply.lines.size(), 2u);
}

// XON (0x11) and XOFF (0x13) are dropped before the ACK, inside the text and after the prompt.
TEST(RaplReplyReader, XonXoffDropped) {
  ReplyReader reader;
  feed_all(reader,
           "\x11\x13\x06\x11\r\nA\x13"
           "B\r\n>\x11>");
  ASSERT_TRUE(reader.complete());
  EXPECT_EQ(reader.reply().lines, (std::vector<std::string>{"AB"}));
  EXPECT_NO_THROW(reader.feed(0x11));
  EXPECT_NO_THROW(reader.feed(0x13));
  EXPECT_TRUE(reader.complete());
}

// CR and LF before the ACK (an echoed CR) are tolerated.
TEST(RaplReplyReader, CrLfBeforeAckTolerated) {
  ReplyReader reader;
  feed_all(reader, "\r\n\r");
  EXPECT_FALSE(reader.acknowledged());
  reader.feed(0x06);
  EXPECT_TRUE(reader.acknowledged());
  feed_all(reader, "\r\n>>");
  EXPECT_TRUE(reader.complete());
  EXPECT_TRUE(reader.reply().lines.empty());
}

// Anything but ACK, CR, LF, XON or XOFF before the ACK is an error.
TEST(RaplReplyReader, GarbageBeforeAckIsError) {
  for (uint8_t byte : {uint8_t{'X'}, uint8_t{'>'}, uint8_t{0x15}, uint8_t{0x00}, uint8_t{0xFF}}) {
    ReplyReader reader;
    EXPECT_THROW(reader.feed(byte), RaplError) << int{byte};
    EXPECT_FALSE(reader.acknowledged());
  }
}

// A byte other than XON/XOFF after the prompt is an error.
TEST(RaplReplyReader, ByteAfterPromptIsError) {
  ReplyReader reader;
  feed_all(reader, "\x06\r\n>>");
  ASSERT_TRUE(reader.complete());
  EXPECT_THROW(reader.feed('x'), RaplError);
}

// The reply cannot be read before the prompt, and reset starts over.
TEST(RaplReplyReader, ReplyBeforePromptAndReset) {
  ReplyReader reader;
  feed_all(reader, "\x06TEXT\r\n>");
  EXPECT_FALSE(reader.complete());
  EXPECT_THROW(reader.reply(), RaplError);
  reader.reset();
  EXPECT_FALSE(reader.acknowledged());
  EXPECT_FALSE(reader.complete());
  EXPECT_THROW(reader.feed('T'), RaplError);  // a fresh reader wants the ACK first
  reader.reset();
  feed_all(reader, "\x06OK\r\n>>");
  ASSERT_TRUE(reader.complete());
  EXPECT_EQ(reader.reply().lines, (std::vector<std::string>{"OK"}));
}

// A reply of more than 4096 bytes without a prompt is an error.
TEST(RaplReplyReader, OverLongReply) {
  ReplyReader reader;
  reader.feed(0x06);
  for (int i = 0; i < 4096; ++i) reader.feed('A');
  EXPECT_FALSE(reader.complete());
  EXPECT_THROW(reader.feed('A'), RaplError);
}

// ---- parse_reply_text ----

// Lines split at CR and/or LF, empty lines dropped.
TEST(RaplParseReplyText, SplitsLines) {
  const Reply reply = parse_reply_text("\r\nONE\r\n\r\nTWO\nTHREE\rFOUR");
  EXPECT_EQ(reply.lines, (std::vector<std::string>{"ONE", "TWO", "THREE", "FOUR"}));
  EXPECT_FALSE(reply.error.has_value());
  EXPECT_TRUE(parse_reply_text("").lines.empty());
  EXPECT_TRUE(parse_reply_text("\r\n\r\n").lines.empty());
}

// ---- parse_joints ----

// A JOINTS line in degrees becomes radians, with spaces or commas, any case, after other lines.
TEST(RaplParseJoints, WellFormed) {
  const JointArray q = parse_joints(reply_of({"JOINTS 10 -20 30.5 0 90 -180"}));
  EXPECT_DOUBLE_EQ(q[0], 10 * kDeg);
  EXPECT_DOUBLE_EQ(q[1], -20 * kDeg);
  EXPECT_DOUBLE_EQ(q[2], 30.5 * kDeg);
  EXPECT_DOUBLE_EQ(q[3], 0.0);
  EXPECT_DOUBLE_EQ(q[4], kPi / 2);
  EXPECT_DOUBLE_EQ(q[5], -kPi);
  const JointArray r = parse_joints(reply_of({"W2", "joints 180,0,0,0,0,45"}));
  EXPECT_DOUBLE_EQ(r[0], kPi);
  EXPECT_DOUBLE_EQ(r[5], kPi / 4);
}

// Too few or too many numbers, NaN, infinity, a non-number or no JOINTS line are errors.
TEST(RaplParseJoints, Malformed) {
  EXPECT_THROW(parse_joints(reply_of({"JOINTS 1 2 3 4 5"})), RaplError);
  EXPECT_THROW(parse_joints(reply_of({"JOINTS 1 2 3 4 5 6 7"})), RaplError);
  EXPECT_THROW(parse_joints(reply_of({"JOINTS"})), RaplError);
  EXPECT_THROW(parse_joints(reply_of({"JOINTS 1 2 3 4 5 nan"})), RaplError);
  EXPECT_THROW(parse_joints(reply_of({"JOINTS 1 2 3 4 5 NaN"})), RaplError);
  EXPECT_THROW(parse_joints(reply_of({"JOINTS 1 2 3 inf 5 6"})), RaplError);
  EXPECT_THROW(parse_joints(reply_of({"JOINTS 1 2 x 4 5 6"})), RaplError);
  EXPECT_THROW(parse_joints(reply_of({"*** 72 LOCATION OUT OF RANGE"})), RaplError);
  EXPECT_THROW(parse_joints(reply_of({})), RaplError);
}

// ---- parse_location ----

// A location line `name x y z r p y` (inches, degrees) becomes metres and radians.
TEST(RaplParseLocation, WellFormed) {
  const Location location = parse_location(reply_of({"P1 1 10 -0.5 180 0 -90"}));
  EXPECT_EQ(location.name, "P1");
  EXPECT_DOUBLE_EQ(location.xyz.x(), 0.0254);
  EXPECT_DOUBLE_EQ(location.xyz.y(), 0.254);
  EXPECT_DOUBLE_EQ(location.xyz.z(), -0.0127);
  EXPECT_DOUBLE_EQ(location.rpy.x(), kPi);
  EXPECT_DOUBLE_EQ(location.rpy.y(), 0.0);
  EXPECT_DOUBLE_EQ(location.rpy.z(), -kPi / 2);
}

// Error lines and lines that are not six numbers are skipped until the location line.
TEST(RaplParseLocation, SkipsOtherLines) {
  const Location location =
      parse_location(reply_of({"*** 1 2 3 4 5 6", "HEADER X Y Z", "Q7 12,0,0,90,0,0"}));
  EXPECT_EQ(location.name, "Q7");
  EXPECT_DOUBLE_EQ(location.xyz.x(), 12 * 0.0254);
  EXPECT_DOUBLE_EQ(location.rpy.x(), kPi / 2);
}

// Leading blanks before the name do not lose the name.
TEST(RaplParseLocation, LeadingBlanks) {
  const Location location = parse_location(reply_of({"  P1 1 10 -0.5 180 0 -90"}));
  EXPECT_EQ(location.name, "P1");
  EXPECT_DOUBLE_EQ(location.xyz.x(), 0.0254);
}

// A tab after the name ends it, as it ends the verb (fuzz/rapl_fuzz: the name took the first
// number, and the location printed again no longer parsed).
TEST(RaplParseLocation, TabAfterTheName) {
  const Location location = parse_location(reply_of({"P1\t1 10 -0.5 180 0 -90"}));
  EXPECT_EQ(location.name, "P1");
  EXPECT_EQ(parse_location(reply_of({format_location_reply(location)})).name, "P1");
}

// Too few numbers, NaN, a non-number, an error only or nothing are errors.
TEST(RaplParseLocation, Malformed) {
  EXPECT_THROW(parse_location(reply_of({"P1 1 2 3 4 5"})), RaplError);
  EXPECT_THROW(parse_location(reply_of({"P1 1 2 3 4 5 6 7"})), RaplError);
  EXPECT_THROW(parse_location(reply_of({"P1 1 2 3 4 5 nan"})), RaplError);
  EXPECT_THROW(parse_location(reply_of({"P1 1 2 3 -inf 5 6"})), RaplError);
  EXPECT_THROW(parse_location(reply_of({"P1 1 2 3 four 5 6"})), RaplError);
  EXPECT_THROW(parse_location(reply_of({"*** 72 LOCATION OUT OF RANGE"})), RaplError);
  EXPECT_THROW(parse_location(reply_of({"P1"})), RaplError);
  EXPECT_THROW(parse_location(reply_of({})), RaplError);
}

// ---- Controller-side formatting ----

// The W2 reply text in degrees with four decimals, space separated.
TEST(RaplFormat, JointsReply) {
  const JointArray q{0.0, kPi / 2, -kPi / 4, kPi, kPi / 6, -kPi / 3};
  EXPECT_EQ(format_joints_reply(q), "JOINTS 0.0000 90.0000 -45.0000 180.0000 30.0000 -60.0000");
}

// The LLOC reply text in inches and degrees with four decimals, space separated.
TEST(RaplFormat, LocationReply) {
  Location location;
  location.name = "P1";
  location.xyz = {0.0254, 0.254, -0.0127};
  location.rpy = {kPi, 0.0, -kPi / 2};
  EXPECT_EQ(format_location_reply(location), "P1 1.0000 10.0000 -0.5000 180.0000 0.0000 -90.0000");
}

// Joints formatted by the controller side parse back within the %.4f rounding (0.00005 deg).
TEST(RaplFormat, JointsRoundTrip) {
  const JointArray q{0.1234, -1.5, 2.9, -3.1, 0.0, 1e-3};
  const JointArray back = parse_joints(reply_of({format_joints_reply(q)}));
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(back[i], q[i], 0.00005 * kDeg) << i;
  // Whole degrees survive exactly up to the conversion's rounding.
  const JointArray whole{10 * kDeg, -20 * kDeg, 30 * kDeg, -40 * kDeg, 50 * kDeg, -60 * kDeg};
  const JointArray whole_back = parse_joints(reply_of({format_joints_reply(whole)}));
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(whole_back[i], whole[i]) << i;
}

// A location formatted by the controller side parses back within 0.00005 in and 0.00005 deg.
TEST(RaplFormat, LocationRoundTrip) {
  Location location;
  location.name = "GRASP";
  location.xyz = {0.45, -0.1234567, 0.3};
  location.rpy = {kPi, -0.7, 0.25};
  const Location back = parse_location(reply_of({format_location_reply(location)}));
  EXPECT_EQ(back.name, "GRASP");
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(back.xyz[i], location.xyz[i], 0.00005 * 0.0254) << i;
    EXPECT_NEAR(back.rpy[i], location.rpy[i], 0.00005 * kDeg) << i;
  }
}

// ---- split_command / parse_numbers ----

// The verb is upper-cased and separated from the rest at the first space.
TEST(RaplSplitCommand, VerbAndRest) {
  const CommandLine move_line = split_command("move P1");
  EXPECT_EQ(move_line.verb, "MOVE");
  EXPECT_EQ(move_line.rest, "P1");
  const CommandLine ma = split_command("  MA 1,2,3,4,5,6");
  EXPECT_EQ(ma.verb, "MA");
  EXPECT_EQ(ma.rest, "1,2,3,4,5,6");
  const CommandLine tabbed = split_command("MA\t1,2,3,4,5,6");  // a tab separates the verb too
  EXPECT_EQ(tabbed.verb, "MA");
  EXPECT_EQ(tabbed.rest, "1,2,3,4,5,6");
  const CommandLine w2 = split_command("w2");
  EXPECT_EQ(w2.verb, "W2");
  EXPECT_EQ(w2.rest, "");
  const CommandLine point_line = split_command("POINT P1 1,2,3,4,5,6");
  EXPECT_EQ(point_line.verb, "POINT");
  EXPECT_EQ(point_line.rest, "P1 1,2,3,4,5,6");
  const CommandLine empty = split_command("");
  EXPECT_EQ(empty.verb, "");
  EXPECT_EQ(empty.rest, "");
}

// Numbers separated by commas, spaces and tabs, in any mix.
TEST(RaplParseNumbers, WellFormed) {
  EXPECT_EQ(parse_numbers("1,2 3"), (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(parse_numbers(" 1, -2.5,,3e2\t0.125 "), (std::vector<double>{1, -2.5, 300, 0.125}));
  EXPECT_TRUE(parse_numbers("").empty());
  EXPECT_TRUE(parse_numbers(" ,\t, ").empty());
}

// A field that is not a finite number is an error naming the field.
TEST(RaplParseNumbers, Malformed) {
  EXPECT_THROW(parse_numbers("1,x"), RaplError);
  EXPECT_THROW(parse_numbers("nan"), RaplError);
  EXPECT_THROW(parse_numbers("1 inf"), RaplError);
  EXPECT_THROW(parse_numbers("1.5.2"), RaplError);
  EXPECT_THROW(parse_numbers("1e999"), RaplError);
  EXPECT_THROW(parse_numbers("12abc"), RaplError);
  try {
    parse_numbers("1, 2, bad, 4");
    ADD_FAILURE() << "no RaplError";
  } catch (const RaplError& e) {
    EXPECT_NE(std::string(e.what()).find("'bad'"), std::string::npos) << e.what();
  }
}

// A garbled number's error names it in printable ASCII: the byte 0xdc from the line reads \xdc,
// so no raw serial byte reaches a log or ARM_STATUS.error.
TEST(RaplErrors, GarbledBytesArePrintedEscaped) {
  try {
    parse_numbers("0.0\xdc" "00 1.5");
    FAIL() << "a garbled number was parsed";
  } catch (const RaplError& e) {
    EXPECT_STREQ(e.what(), "'0.0\\xdc00' is not a number");
  }
  EXPECT_EQ(printable(std::string("a\r\n\x7f\x00z", 6)), "a\\x0d\\x0a\\x7f\\x00z");
}

}  // namespace
}  // namespace sg::arm::rapl
