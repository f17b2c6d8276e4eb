#pragma once

/// What the fuzz targets share (docs/fuzzing.md).
///
///     SG_FUZZ_CHECK(encoded == input, "header re-encodes to %zu other bytes", n);
///     sg::fuzz::MemoryFile file;                        // a memfd, reused by every run
///     reader.read(file.write(data, size));              // its /proc/self/fd path

#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

/// A property a target asserts beyond not crashing. A violation prints what failed and aborts,
/// which libFuzzer reports as a crash and saves the input under -artifact_prefix.
#define SG_FUZZ_CHECK(condition, ...)                                           \
  do {                                                                          \
    if (!(condition)) {                                                         \
      std::fprintf(stderr, "fuzz check failed: %s: ", #condition);              \
      std::fprintf(stderr, __VA_ARGS__);                                        \
      std::fputc('\n', stderr);                                                 \
      std::abort();                                                             \
    }                                                                           \
  } while (0)

namespace sg::fuzz {

/// An anonymous in-memory file (memfd_create) for loaders that take a path: write() replaces its
/// contents and returns `/proc/self/fd/N`, which every open() of it reads from the start.
class MemoryFile {
 public:
  MemoryFile() : fd_(memfd_create("sg-fuzz", 0)) {
    if (fd_ < 0) {
      std::perror("memfd_create");
      std::abort();
    }
    path_ = "/proc/self/fd/" + std::to_string(fd_);
  }
  ~MemoryFile() { close(fd_); }
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;

  const std::string& write(const uint8_t* data, size_t size) {
    if (ftruncate(fd_, 0) != 0 || pwrite(fd_, data, size, 0) != static_cast<ssize_t>(size)) {
      std::perror("memfd write");
      std::abort();
    }
    return path_;
  }
  const std::string& path() const { return path_; }

 private:
  int fd_;
  std::string path_;
};

}  // namespace sg::fuzz
