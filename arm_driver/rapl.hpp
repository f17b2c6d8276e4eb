#pragma once

/// RAPL-II, the C550's command language, as text: the commands sg-arm-driver sends, the replies
/// it parses, and the parsing the emulator needs. Pure functions, no I/O (docs/arm.md).
///
///     std::string line = rapl::move_joints(q);          // "MA 10.0000,-20.0000,..." (degrees)
///     rapl::ReplyReader reader;                         // after the CR has been echoed:
///     for (uint8_t byte : received) reader.feed(byte);  // ACK, text, CR LF ">>"
///     if (reader.complete()) joints = rapl::parse_joints(reader.reply());

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace sg::arm::rapl {

inline constexpr uint8_t CR = '\r', LF = '\n', XON = 0x11, XOFF = 0x13, CTRL_C = 0x03,
                         CTRL_Z = 0x1A, ACK = 0x06;
/// What ends every reply.
inline constexpr std::string_view kPrompt = "\r\n>>";
/// Longest command line accepted (the controller's line buffer is not documented; this is ours).
inline constexpr size_t kMaxLine = 120;

/// A malformed command or reply; the message names what was expected and what came.
/// `text` with every byte outside printable ASCII written as \xNN: what a garbled serial line
/// put into an error message reaches logs and ARM_STATUS as readable ASCII, never raw bytes.
std::string printable(std::string_view text);

class RaplError : public std::runtime_error {
 public:
  explicit RaplError(std::string_view what) : std::runtime_error(printable(what)) {}
};

/// Joint angles in radians (joint 1..6).
using JointArray = std::array<double, 6>;

// ---- Commands (no trailing CR) ----
std::string speed(int percent);                        ///< "SPEED 50"
std::string move_joints(const JointArray& radians);    ///< "MA j1,...,j6" degrees, %.4f
std::string point(const std::string& name, const Eigen::Vector3d& xyz_metres,
                  const Eigen::Vector3d& rpy_radians);  ///< "POINT name x,y,z,r,p,y" in, deg
std::string move(const std::string& name);             ///< "MOVE name"
std::string lloc(const std::string& name);             ///< "LLOC name"

// ---- Replies ----
/// The text of one reply: its lines, and the controller's error when a line starts with "***".
struct Reply {
  std::vector<std::string> lines;
  std::optional<std::string> error;
};

/// Assembles a reply byte by byte: an ACK first (XON/XOFF dropped anywhere, CR/LF before the ACK
/// dropped too), then text, then CR LF ">>". Throws RaplError on anything but ACK before the text, or an over-long reply.
class ReplyReader {
 public:
  void feed(uint8_t byte);
  bool acknowledged() const { return acknowledged_; }
  bool complete() const { return complete_; }
  /// The parsed reply; valid once complete().
  Reply reply() const;
  void reset();

 private:
  bool acknowledged_ = false;
  bool complete_ = false;
  std::string text_;
};

/// Splits reply text (between the ACK and the prompt) into non-empty lines and finds an error.
Reply parse_reply_text(std::string_view text);

/// The joints of a `W2` reply: a line `JOINTS j1 j2 j3 j4 j5 j6` (degrees), returned in radians.
JointArray parse_joints(const Reply& reply);

/// A location: tool position (metres) and orientation roll, pitch, yaw (radians).
struct Location {
  std::string name;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
};
/// The location of an `LLOC name` reply: a line `name x y z r p y` (inches, degrees).
Location parse_location(const Reply& reply);

// ---- For the controller's side ----
/// A command line split into its verb (upper case) and the rest.
struct CommandLine {
  std::string verb;
  std::string rest;
};
CommandLine split_command(std::string_view line);
/// Numbers separated by commas and/or spaces; throws RaplError naming the bad field.
std::vector<double> parse_numbers(std::string_view text);
/// Reply text lines for the controller to send.
std::string format_joints_reply(const JointArray& radians);  ///< "JOINTS j1 ... j6" degrees
std::string format_location_reply(const Location& location);

}  // namespace sg::arm::rapl
