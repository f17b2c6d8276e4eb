#include "arm_driver/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace sg::arm {
namespace {

speed_t baud_constant(int baud) {
  switch (baud) {
    case 1200: return B1200;
    case 2400: return B2400;
    case 4800: return B4800;
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    default: throw std::invalid_argument("unsupported baud rate " + std::to_string(baud));
  }
}

tcflag_t size_flag(int bits) {
  switch (bits) {
    case 5: return CS5;
    case 6: return CS6;
    case 7: return CS7;
    case 8: return CS8;
    default: throw std::invalid_argument("unsupported data bits " + std::to_string(bits));
  }
}

void configure(int fd, const SerialSettings& s) {
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) throw std::runtime_error(std::strerror(errno));
  ::cfmakeraw(&tio);
  tio.c_cflag &= ~(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
  tio.c_cflag |= CLOCAL | CREAD | size_flag(s.data_bits);
  if (s.parity == 'E' || s.parity == 'O') tio.c_cflag |= PARENB;
  if (s.parity == 'O') tio.c_cflag |= PARODD;
  if (s.stop_bits == 2) tio.c_cflag |= CSTOPB;
  tio.c_iflag &= ~(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 0;  // reads never block: poll(2) does the waiting
  tio.c_cc[VTIME] = 0;
  const speed_t speed = baud_constant(s.baud);
  ::cfsetispeed(&tio, speed);
  ::cfsetospeed(&tio, speed);
  if (::tcsetattr(fd, TCSANOW, &tio) != 0) throw std::runtime_error(std::strerror(errno));
}

}  // namespace

std::string describe(const SerialSettings& s) {
  return std::to_string(s.baud) + " " + std::to_string(s.data_bits) + s.parity +
         std::to_string(s.stop_bits);
}

void parse_framing(const std::string& text, SerialSettings& settings) {
  if (text.size() != 3 || text[0] < '5' || text[0] > '8' ||
      std::string("NEO").find(text[1]) == std::string::npos || (text[2] != '1' && text[2] != '2')) {
    throw std::invalid_argument("serial framing '" + text + "' is not like 8N1 (bits 5-8, parity " +
                                "N/E/O, stop 1 or 2)");
  }
  settings.data_bits = text[0] - '0';
  settings.parity = text[1];
  settings.stop_bits = text[2] - '0';
}

std::unique_ptr<SerialPort> SerialPort::open(const std::string& path,
                                             const SerialSettings& settings) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  if (!::isatty(fd)) {
    ::close(fd);
    throw std::runtime_error(path + " is not a serial device (not a terminal)");
  }
  try {
    configure(fd, settings);
  } catch (const std::exception& e) {
    ::close(fd);
    throw std::runtime_error("cannot configure " + path + " as " + describe(settings) + ": " +
                             e.what());
  }
  ::tcflush(fd, TCIOFLUSH);
  return std::unique_ptr<SerialPort>(new SerialPort(fd, path));
}

SerialPort::~SerialPort() {
  if (fd_ >= 0) ::close(fd_);
}

void SerialPort::gone(const std::string& what) const {
  throw LinkDown(path_ + ": " + what);
}

void SerialPort::write(std::span<const uint8_t> bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
    } else if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      pollfd p{fd_, POLLOUT, 0};
      ::poll(&p, 1, 100);
      if (p.revents & (POLLHUP | POLLERR)) gone("hung up while writing");
    } else {
      gone(std::string("write failed: ") + std::strerror(errno));
    }
  }
}

std::optional<uint8_t> SerialPort::read_byte(std::chrono::microseconds timeout) {
  if (next_ < buffer_.size()) return buffer_[next_++];
  pollfd p{fd_, POLLIN, 0};
  const int ms = static_cast<int>((timeout.count() + 999) / 1000);
  const int ready = ::poll(&p, 1, ms);
  if (ready < 0) {
    if (errno == EINTR) return std::nullopt;
    gone(std::string("poll failed: ") + std::strerror(errno));
  }
  if (ready == 0) return std::nullopt;
  if (!(p.revents & POLLIN)) gone("hung up");
  buffer_.resize(256);
  const ssize_t n = ::read(fd_, buffer_.data(), buffer_.size());
  if (n <= 0) {
    const int error = errno;
    // Nothing was read: leave no unread bytes behind, or the next call would return the stale
    // or zero-filled buffer instead of reporting the device gone again.
    buffer_.clear();
    next_ = 0;
    if (n == 0) gone("end of file");
    if (error == EAGAIN || error == EINTR) return std::nullopt;
    gone(std::string("read failed: ") + std::strerror(error));
  }
  buffer_.resize(static_cast<size_t>(n));
  next_ = 1;
  return buffer_[0];
}

void SerialPort::discard_input() {
  buffer_.clear();
  next_ = 0;
  ::tcflush(fd_, TCIFLUSH);
}

}  // namespace sg::arm
