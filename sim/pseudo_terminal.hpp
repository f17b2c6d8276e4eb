#pragma once

#include <string>

namespace sg::sim {

/// A pseudo-terminal whose slave side is raw at 38,400 baud, the master side non-blocking: the
/// serial line sg-c550-sim offers. It keeps a slave descriptor open itself, so the master never
/// reads EIO while no driver has the device open. Throws std::runtime_error naming the call that
/// failed.
class PseudoTerminal {
 public:
  PseudoTerminal();
  ~PseudoTerminal();
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  int master() const { return master_; }
  /// The slave device, /dev/pts/N: what a driver opens.
  const std::string& path() const { return path_; }

 private:
  void make_raw();
  void close_all();

  int master_ = -1;
  int slave_ = -1;
  std::string path_;
};

/// A symlink `path` -> target, replaced atomically by point_to(); remove() (and the destructor)
/// unlinks it if it still points at the last target. An empty path does nothing.
class Symlink {
 public:
  explicit Symlink(std::string path) : path_(std::move(path)) {}
  ~Symlink() { remove(); }
  Symlink(const Symlink&) = delete;
  Symlink& operator=(const Symlink&) = delete;

  void point_to(const std::string& target);
  void remove();

 private:
  std::string path_;
  std::string target_;
};

}  // namespace sg::sim
