#pragma once

/// A byte stream with read time-outs: what the C550 link layer talks through. SerialPort is the
/// real one (a serial device, or sg-c550-sim's pseudo-terminal); tests may put a pipe behind it.
///
///     std::unique_ptr<ByteStream> line = SerialPort::open("/dev/ttyS0", {});
///     line->write(bytes);
///     std::optional<uint8_t> byte = line->read_byte(std::chrono::milliseconds(200));

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>

namespace sg::arm {

/// The device has gone: unplugged, hung up, closed at the other end (EIO, POLLHUP, end of file).
/// The driver closes the stream and reconnects.
class LinkDown : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ByteStream {
 public:
  virtual ~ByteStream() = default;
  /// Writes every byte; throws LinkDown when the device has gone.
  virtual void write(std::span<const uint8_t> bytes) = 0;
  /// One byte, waiting at most `timeout`; nullopt on time-out; throws LinkDown.
  virtual std::optional<uint8_t> read_byte(std::chrono::microseconds timeout) = 0;
  /// Drops whatever has arrived and not been read.
  virtual void discard_input() = 0;
};

}  // namespace sg::arm
