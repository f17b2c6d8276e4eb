#pragma once

/// A serial port with termios: raw mode (no echo, no line editing, no CR/LF translation, no
/// flow control), 38,400 baud 8N1 by default, reads with time-outs through poll(2), and a vanished
/// device (EIO, hang-up, end of file) reported as LinkDown.
///
///     SerialSettings settings;                 // 38400 8N1
///     auto port = SerialPort::open("/dev/ttyUSB0", settings);
///     port->write(std::as_bytes(...));

#include <memory>
#include <string>
#include <vector>

#include "arm_driver/byte_stream.hpp"

namespace sg::arm {

struct SerialSettings {
  int baud = 38400;        ///< one of the standard POSIX rates, 1200..230400
  int data_bits = 8;       ///< 5..8
  char parity = 'N';       ///< 'N', 'E' or 'O'
  int stop_bits = 1;       ///< 1 or 2
};

/// "38400 8N1": for logs.
std::string describe(const SerialSettings& settings);
/// Parses "8N1"-style framing into `settings`; throws std::invalid_argument naming the text.
void parse_framing(const std::string& text, SerialSettings& settings);

class SerialPort final : public ByteStream {
 public:
  /// Opens and configures `path`; throws std::runtime_error naming the path and the reason
  /// (no such device, permission, not a terminal, unsupported baud).
  static std::unique_ptr<SerialPort> open(const std::string& path, const SerialSettings& settings);
  ~SerialPort() override;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  void write(std::span<const uint8_t> bytes) override;
  std::optional<uint8_t> read_byte(std::chrono::microseconds timeout) override;
  void discard_input() override;

  const std::string& path() const { return path_; }

 private:
  SerialPort(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  [[noreturn]] void gone(const std::string& what) const;

  int fd_ = -1;
  std::string path_;
  std::vector<uint8_t> buffer_;
  size_t next_ = 0;  ///< next unread byte of buffer_
};

}  // namespace sg::arm
