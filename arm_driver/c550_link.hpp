#pragma once

/// The host side of the C550 serial line: ACI enquiry and memory transfers (stop-and-wait with
/// retries), the host session, and RAPL-II commands with every echo checked (docs/arm.md).
///
///     auto port = SerialPort::open("/dev/ttyS0", {});
///     C550Link link(*port);
///     link.open_session();                                   // ACI 0x48 read, ^C, NOH
///     link.command(rapl::move_joints(q), LinkTiming{}.motion_reply);   // echo, CR, ACK, ">>"
///     rapl::JointArray q_now = link.read_joints();           // W2

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "arm_driver/aci.hpp"
#include "arm_driver/byte_stream.hpp"
#include "arm_driver/rapl.hpp"
#include "common/clock.hpp"

namespace sg::arm {

using std::chrono::milliseconds;

/// Time-outs and retries of the link. The defaults suit 38,400 baud and the controller's 0.72-0.84
/// s answer to a motion command.
struct LinkTiming {
  milliseconds byte_timeout{200};      ///< an echo, an ACK to a header or block, the next byte
  milliseconds reply_timeout{1000};    ///< the ACK of a command that does not move the arm
  milliseconds motion_reply{3000};     ///< the ACK of a motion command (held by the controller)
  milliseconds session_settle{100};    ///< after the session byte, before ^C; and ^C's prompt
  int enquiry_tries = 32;
  int retries = 3;                     ///< per header and per block
};

/// A protocol fault the link could not recover: no answer, a wrong echo, a bad frame after every
/// retry. The line is still there; the caller may resynchronise and try again.
class LinkError : public std::runtime_error {
 public:
  explicit LinkError(std::string_view what) : std::runtime_error(rapl::printable(what)) {}
};

/// The controller understood the command and refused it: a `***` reply line.
class ControllerError : public std::runtime_error {
 public:
  explicit ControllerError(std::string_view what) : std::runtime_error(rapl::printable(what)) {}
};

/// Counters for status and benchmarks.
struct LinkStats {
  int64_t bytes_written = 0;
  int64_t bytes_read = 0;
  int64_t retries = 0;      ///< headers, blocks and enquiries sent again
  int64_t resyncs = 0;      ///< commands abandoned with ^C after a bad echo or reply
};

class C550Link {
 public:
  /// Speaks to controller `slave` over `line`, waiting (settle times, drains) on `clock`; the
  /// line's own read time-outs are the line's (a SerialPort's are real, a simulated line's run
  /// the simulated clock).
  explicit C550Link(ByteStream& line, int slave = 1, LinkTiming timing = {},
                    Clock& clock = system_clock());

  /// `'R', s+0x20, ENQ` until the controller answers `'R', s+0x20, ACK` (enquiry_tries).
  void enquire();
  /// ACI memory transfers of 1..32768 bytes.
  std::vector<uint8_t> read_memory(uint8_t memtype, uint16_t segment, uint16_t offset,
                                   int length);
  void write_memory(uint8_t memtype, uint16_t segment, uint16_t offset,
                    const std::vector<uint8_t>& data);

  /// Opens the host session: first leave_command_mode() (a driver that died mid-session leaves the
  /// controller in RAPL-II mode, where an enquiry is just text), then the enquiry, the one-byte
  /// 0x48 read, ^C, and `NOH`.
  void open_session();
  /// Closes it: `HELP`, then 0x1A twice (the controller returns to ACI mode).
  void close_session();

  /// Sends one RAPL-II command and returns its reply. Each character's echo is checked before the
  /// next is sent; on a wrong or missing echo the line is cancelled with ^C (nothing was
  /// executed) and LinkError is thrown with `delivered() == false`. Once the CR is out the command
  /// counts as delivered: a garbled or missing reply after it throws LinkError with
  /// `delivered() == true`, and a `***` reply throws ControllerError.
  rapl::Reply command(const std::string& line, milliseconds reply_timeout);
  /// True when the last command's CR reached the line (it may have been executed).
  bool delivered() const { return delivered_; }

  /// `W2`: the joints, radians.
  rapl::JointArray read_joints();
  /// `LLOC name`.
  rapl::Location read_location(const std::string& name);

  /// ^C, `HELP`, ^Z ^Z without waiting for answers: returns a controller in RAPL-II mode to ACI
  /// mode; in ACI mode these bytes are not frames and are ignored.
  void leave_command_mode();

  /// ^C, then everything up to the prompt (or a quiet byte_timeout) is dropped.
  void resynchronise();

  const LinkStats& stats() const { return stats_; }
  const LinkTiming& timing() const { return timing_; }

 private:
  void send(std::span<const uint8_t> bytes);
  void drain(double at_most_seconds);
  /// One byte as it came: the ACI layer is binary, so 0x11 and 0x13 are data there.
  uint8_t expect_raw(const char* what, milliseconds timeout);
  /// One byte of RAPL-II text, XON/XOFF dropped (c550-aci.md: "dropped on read").
  uint8_t expect_text(const char* what, milliseconds timeout);
  std::vector<uint8_t> read_exact(size_t n, const char* what);
  void send_header(const aci::AciHeader& header);
  void send_blocks(const std::vector<uint8_t>& data);
  std::vector<uint8_t> receive_blocks(int length);
  void echo_line(const std::string& line);

  ByteStream& line_;
  int slave_;
  LinkTiming timing_;
  LinkStats stats_;
  Clock& clock_;
  bool delivered_ = false;
};

}  // namespace sg::arm
