#pragma once

/// The bytes a C550 speaks on its serial line, as docs/arm.md implements the protocol: ACI
/// enquiry, headers and block transfers, the host session, and RAPL-II commands with echo, ACK,
/// reply text and prompt. Pure: no I/O, no clock, no threads. The shell feeds each byte received
/// with the time it arrived and writes what take_output() returns once next_output_time() has
/// come.
///
///     sg::sim::C550Controller controller(sg::arm::ArmGeometry::a465());
///     sg::sim::C550Emulator c550(controller, /*slave=*/1);
///     for (uint8_t byte : received) c550.feed(byte, now);
///     if (c550.next_output_time() <= now) write(c550.take_output(now));
///
/// Byte behaviour where docs/arm.md leaves room (modelled, not known from the real C550):
///  - ACI: garbage before SOH is ignored; a header (13 bytes from SOH) is NAKed for bad framing
///    or LRC, a wrong host id or slave number, a bad layout, or a transfer the memory model
///    refuses (unknown memory type, past the end, a write to read-only memory). An enquiry for
///    another slave gets no answer. On a host read the first block follows the header's ACK at
///    once; a NAK resends the same block, and the third NAK of one block abandons the transfer
///    (silently: back to waiting for an enquiry or a header). After the last block's ACK the
///    emulator sends EOT and waits for the host's EOT echo. On a host write good blocks are
///    ACKed and bad ones (framing, LRC, wrong size or end byte) NAKed; the data is written when
///    the host's EOT arrives; an EOT before the last block abandons the write. Blocks carry no
///    sequence number: a block the host resends because our ACK was lost is taken as the next
///    one (the last block resent is ACKed again and written once). SOH or an enquiry between
///    blocks restarts (the host retrying from the top). A silence of more than 100 ms inside a
///    header or block abandons the partial frame (an inter-character time-out).
///  - Session: the 1-byte memtype 0x48 read enters RAPL mode when the host echoes the EOT; a
///    ^C (0x03) instead of the echo also enters it (and gets its prompt). Any other byte there
///    is handled as in ACI mode (e.g. the host retrying the enquiry because our EOT was lost).
///  - RAPL: printable characters (0x20..0x7E) are echoed at once, one by one. CR is NOT echoed:
///    it ends the line, and the next byte the host sees is the ACK. LF, NUL, backspace, ENQ,
///    EOT and other control bytes are dropped silently (not echoed, not stored); XON/XOFF too.
///    ^C clears the line and answers the prompt `\r\n>>` (no ACK). After CR the reply is ACK,
///    then each text line preceded by `\r\n`, then `\r\n>>` (an empty line gets ACK and the
///    prompt). MA, MOVE, READY, OPEN, CLOSE and JOINT are digested for interaction_delay(): the
///    controller executes them at t + delay (the motion or gripper stroke starts then, a CLOSE
///    grasps the ball where it is then) and only then answers, with ACK and prompt or with the
///    `***` line of a refusal (bad arguments, limits, out of range). FINISH answers when the arm
///    and gripper have settled. Everything else answers at once. While a reply is held every byte
///    that arrives (even ^C) is buffered, not echoed, and processed in order after the reply has
///    gone, as if it had arrived then.
///  - A line of more than rapl::kMaxLine characters is echoed in full and answered at its CR by
///    `*** 10 LINE TOO LONG ...`. After HELP, two 0x1A (^Z) in a row return to ACI mode; ^Z at
///    any other time is dropped.

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "arm_driver/aci.hpp"
#include "arm_driver/rapl.hpp"
#include "sim/c550_controller.hpp"

namespace sg::sim {

class C550Emulator {
 public:
  /// Bytes written in one go; `ack` marks a lone protocol ACK (the shell's fault injection drops
  /// only those).
  struct Chunk {
    std::vector<uint8_t> bytes;
    bool ack = false;
  };

  /// Speaks for `controller` (which must outlive it) as slave `slave` (1..127), starting in ACI
  /// mode as after power-up. Throws std::invalid_argument for a bad slave number.
  explicit C550Emulator(C550Controller& controller, int slave = 1);

  /// One byte from the host, received at `t` (seconds, not decreasing).
  void feed(uint8_t byte, double t);
  /// Every byte due by `t`, in order.
  std::vector<uint8_t> take_output(double t);
  /// The same, in the chunks they were produced in.
  std::vector<Chunk> take_output_chunks(double t);
  /// When the next output is due; +infinity when none is queued.
  double next_output_time() const;

  /// True in RAPL mode (after the session byte, until HELP and ^Z ^Z).
  bool in_session() const { return mode_ == Mode::kRapl; }
  /// Every RAPL command line received whole (up to its CR, which is not included), in order,
  /// whether it succeeded or answered `***`; empty lines and lines cancelled by ^C are not
  /// included, an over-long line is cut at kMaxLine and marked "...". Tests use it to check
  /// that no command ran twice.
  std::vector<std::string> executed_commands() const { return executed_; }
  /// Protocol events since the last call (NAKs and why, abandoned transfers, refused commands),
  /// one line each, for the shell's log.
  std::vector<std::string> take_events();

  /// The ball's true centre (base frame, metres) that CLOSE may grasp; nullopt when unknown.
  void set_ball_centre(const std::optional<Eigen::Vector3d>& centre) { ball_ = centre; }

 private:
  enum class Mode { kAci, kRapl };
  enum class Aci { kIdle, kHeader, kSending, kAwaitEot, kReceiving };
  struct Output {
    double due = 0;
    Chunk chunk;
  };
  struct Input {
    uint8_t byte = 0;
    double t = 0;
  };
  /// What a command answers: its text lines, and when (nullopt: at once).
  struct Answer {
    std::vector<std::string> lines;
    std::optional<double> due;
  };

  void pump(double now);
  void process(uint8_t byte, double t);
  void emit(std::vector<uint8_t> bytes, double due, bool ack = false);
  void event(std::string text);

  // ACI
  void aci_byte(uint8_t byte, double t);
  /// Idle handling: SOH starts a header, an enquiry for this slave is answered.
  void aci_restart(uint8_t byte, double t);
  void header_byte(uint8_t byte, double t);
  void accept_header(const arm::aci::AciHeader& header, double t);
  void send_block(double t);
  void sending_byte(uint8_t byte, double t);
  void receiving_byte(uint8_t byte, double t);
  void finish_received_block(double t);
  void to_idle();

  // RAPL
  void rapl_byte(uint8_t byte, double t);
  void end_line(double t);
  Answer execute(const std::string& line, double t);
  /// True for the motion commands the controller executes after interaction_delay().
  static bool acts_after_delay(const std::string& line);
  /// Executes the held motion command once its time has come.
  void run_deferred(double now);
  /// ACK, the reply lines and the prompt, due at `t` (or the answer's own time).
  void reply(const std::string& line, const Answer& answer, double t);
  /// A motion command's answer: its error or nothing.
  Answer motion(const CommandResult& result, double t);
  // One per command: `rest` is the text after the verb, trimmed. Bad arguments throw RaplError.
  Answer speed(const std::string& rest, double t);
  Answer move_absolute(const std::string& rest, double t);  ///< MA
  Answer where(const std::string& rest, double t);          ///< W2
  Answer point(const std::string& rest, double t);
  Answer move(const std::string& rest, double t);
  Answer lloc(const std::string& rest, double t);
  Answer joint(const std::string& rest, double t);
  Answer open(const std::string& rest, double t);
  Answer close(const std::string& rest, double t);
  Answer ready(const std::string& rest, double t);
  Answer abort(const std::string& rest, double t);
  Answer finish(const std::string& rest, double t);
  Answer no_operation(const std::string& rest, double t);  ///< NOH
  Answer help(const std::string& rest, double t);

  C550Controller& controller_;
  int slave_;
  Mode mode_ = Mode::kAci;

  std::deque<Input> input_;
  std::deque<Output> output_;
  double hold_until_ = -std::numeric_limits<double>::infinity();
  /// A motion command received and not yet executed: it runs, and answers, at `due`.
  struct Deferred {
    std::string line;
    double due = 0;
  };
  std::optional<Deferred> deferred_;
  std::vector<std::string> events_;

  // ACI state
  Aci aci_ = Aci::kIdle;
  std::vector<uint8_t> recent_;  ///< the last bytes, to spot an enquiry
  std::vector<uint8_t> frame_;   ///< a header or block being collected
  arm::aci::AciHeader header_;
  std::vector<std::vector<uint8_t>> blocks_;  ///< a host read's frames, or a host write's data
  int block_ = 0;                             ///< the block being sent or received
  int tries_ = 0;                             ///< sends of the current block
  double last_aci_byte_ = 0;                  ///< when the last ACI byte arrived

  // RAPL state
  std::string line_;
  size_t line_length_ = 0;  ///< characters typed, including those past kMaxLine
  bool help_given_ = false;
  int ctrl_z_ = 0;
  std::vector<std::string> executed_;
  std::map<std::string, arm::rapl::Location> locations_;
  std::optional<Eigen::Vector3d> ball_;
};

}  // namespace sg::sim
