#include "sim/pseudo_terminal.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace sg::sim {
namespace {

std::runtime_error system_error(const std::string& what) {
  return std::runtime_error(what + ": " + std::strerror(errno));
}

}  // namespace

PseudoTerminal::PseudoTerminal() {
  master_ = posix_openpt(O_RDWR | O_NOCTTY);
  if (master_ < 0) throw system_error("posix_openpt");
  try {
    if (grantpt(master_) != 0 || unlockpt(master_) != 0)
      throw system_error("grantpt/unlockpt on the pseudo-terminal");
    const char* name = ptsname(master_);
    if (!name) throw system_error("ptsname");
    path_ = name;
    slave_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY);
    if (slave_ < 0) throw system_error(path_ + ": open");
    make_raw();
    if (fcntl(master_, F_SETFL, fcntl(master_, F_GETFL) | O_NONBLOCK) != 0)
      throw system_error("fcntl O_NONBLOCK on the pseudo-terminal");
  } catch (...) {
    close_all();
    throw;
  }
}

PseudoTerminal::~PseudoTerminal() { close_all(); }

void PseudoTerminal::make_raw() {
  termios tio{};
  if (tcgetattr(slave_, &tio) != 0) throw system_error(path_ + ": tcgetattr");
  cfmakeraw(&tio);
  cfsetispeed(&tio, B38400);
  cfsetospeed(&tio, B38400);
  if (tcsetattr(slave_, TCSANOW, &tio) != 0) throw system_error(path_ + ": tcsetattr");
}

void PseudoTerminal::close_all() {
  if (slave_ >= 0) ::close(slave_);
  if (master_ >= 0) ::close(master_);
  slave_ = master_ = -1;
}

void Symlink::point_to(const std::string& target) {
  if (path_.empty()) return;
  const std::string temporary = path_ + ".tmp" + std::to_string(getpid());
  ::unlink(temporary.c_str());
  if (::symlink(target.c_str(), temporary.c_str()) != 0 ||
      ::rename(temporary.c_str(), path_.c_str()) != 0) {
    throw system_error("--link " + path_ + " -> " + target);
  }
  target_ = target;
}

void Symlink::remove() {
  if (path_.empty() || target_.empty()) return;
  std::error_code error;
  if (std::filesystem::read_symlink(path_, error) == target_) ::unlink(path_.c_str());
  target_.clear();
}

}  // namespace sg::sim
