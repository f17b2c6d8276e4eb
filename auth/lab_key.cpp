#include "auth/lab_key.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace sg::auth {
namespace {

constexpr std::size_t kHexSize = 2 * LabKey::kSize;

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw LabKeyError("lab key " + path + ": " + why);
}

std::string errno_text() { return std::strerror(errno); }

/// Closes a file descriptor on scope exit.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

/// Up to `limit` bytes of an open file (the key's text and a little more, to see it is too long).
std::string read_some(int fd, std::size_t limit, const std::string& path) {
  std::string text(limit, '\0');
  std::size_t got = 0;
  while (got < limit) {
    const ssize_t n = ::read(fd, text.data() + got, limit - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(path, "cannot read: " + errno_text());
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  text.resize(got);
  return text;
}

/// The file's mode must leave group and others out: 0600 or 0400.
void check_mode(int fd, const std::string& path) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) fail(path, "cannot stat: " + errno_text());
  if (!S_ISREG(st.st_mode)) fail(path, "not a regular file");
  if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    fail(path, std::string("mode ") + mode +
                   " lets group or others read it; refused (run: chmod 600 " + path + ")");
  }
}

/// Up to `limit` bytes of the secret file at `path`, once it is known to be a regular file that
/// only its owner may read (check_mode).
std::string read_checked(const std::string& path, std::size_t limit) {
  ensure_sodium();
  Fd f{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
  if (f.fd < 0) {
    if (errno == ENOENT) fail(path, "no such file");
    fail(path, "cannot open: " + errno_text());
  }
  check_mode(f.fd, path);
  return read_some(f.fd, limit, path);
}

void write_all(int fd, const std::string& text, const std::string& path) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(path, "cannot write: " + errno_text());
    done += static_cast<std::size_t>(n);
  }
}

/// Creates `path` (which must not exist) holding `text`, mode 0600, on disk before it returns.
void create_exclusive(const std::string& path, const std::string& text) {
  Fd f{::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600)};
  if (f.fd < 0) {
    if (errno == EEXIST)
      fail(path, "already exists; not overwritten (sg-keygen --force replaces it)");
    fail(path, "cannot create: " + errno_text());
  }
  if (::fchmod(f.fd, 0600) != 0) fail(path, "cannot chmod 600: " + errno_text());
  write_all(f.fd, text, path);
  if (::fsync(f.fd) != 0) fail(path, "cannot sync: " + errno_text());
}

}  // namespace

void ensure_sodium() {
  static const int status = sodium_init();  // 0 first time, 1 already; thread-safe
  if (status < 0) throw std::runtime_error("libsodium failed to initialise (sodium_init)");
}

LabKey::LabKey(const std::array<uint8_t, kSize>& bytes) : bytes_(bytes) {}
LabKey::LabKey(const LabKey& other) : bytes_(other.bytes_) {}
LabKey& LabKey::operator=(const LabKey& other) {
  bytes_ = other.bytes_;
  return *this;
}
LabKey::~LabKey() { sodium_memzero(bytes_.data(), bytes_.size()); }

std::string read_secret_file(const std::string& path, std::size_t limit) {
  std::string text = read_checked(path, limit + 1);
  if (text.size() > limit) {
    sodium_memzero(text.data(), text.size());
    fail(path, "more than " + std::to_string(limit) + " bytes");
  }
  return text;
}

void write_secret_file(const std::string& path, const std::string& text) {
  const std::filesystem::path target(path);
  std::error_code ec;
  if (target.has_parent_path() && !std::filesystem::exists(target.parent_path(), ec)) {
    std::filesystem::create_directories(target.parent_path(), ec);
    if (ec) fail(path, "cannot create its folder: " + ec.message());
    std::filesystem::permissions(target.parent_path(), std::filesystem::perms::owner_all, ec);
  }
  const std::string temporary = path + ".new";
  ::unlink(temporary.c_str());
  create_exclusive(temporary, text);
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string why = errno_text();
    ::unlink(temporary.c_str());
    fail(path, "cannot replace: " + why);
  }
}

LabKey command_key(const LabKey& lab) {
  ensure_sodium();
  static constexpr char kDomain[] = "sg-command-v1";
  std::array<uint8_t, LabKey::kSize> bytes{};
  crypto_generichash(bytes.data(), bytes.size(), reinterpret_cast<const unsigned char*>(kDomain),
                     sizeof kDomain - 1, lab.bytes().data(), lab.bytes().size());
  LabKey key(bytes);
  sodium_memzero(bytes.data(), bytes.size());
  return key;
}

LabKey generation_key(const LabKey& lab, uint32_t generation) {
  if (generation == 0) return lab;
  ensure_sodium();
  static constexpr char kDomain[] = "sg-generation-v1";
  unsigned char message[sizeof kDomain - 1 + 4];
  std::memcpy(message, kDomain, sizeof kDomain - 1);
  for (int i = 0; i < 4; ++i)
    message[sizeof kDomain - 1 + i] = static_cast<unsigned char>(generation >> (24 - 8 * i));
  std::array<uint8_t, LabKey::kSize> bytes{};
  crypto_generichash(bytes.data(), bytes.size(), message, sizeof message, lab.bytes().data(),
                     lab.bytes().size());
  LabKey key(bytes);
  sodium_memzero(bytes.data(), bytes.size());
  return key;
}

LabKey LabKey::load(const std::string& path) {
  constexpr std::size_t kLimit = kHexSize + 8;  // enough to tell "too long"
  std::string text = read_checked(path, kLimit);
  const bool cut = text.size() == kLimit;
  if (!text.empty() && text.back() == '\n') text.pop_back();
  if (text.size() != kHexSize) {
    const std::size_t size = text.size();
    sodium_memzero(text.data(), text.size());
    fail(path, "expected 64 hex characters and a newline, got " + std::to_string(size) +
                   (cut ? " or more" : "") + " characters");
  }
  for (char c : text) {
    if (!std::isxdigit(static_cast<unsigned char>(c))) {
      sodium_memzero(text.data(), text.size());
      fail(path, "not hex: expected 64 characters 0-9 a-f");
    }
  }
  LabKey key;
  std::size_t decoded = 0;
  const int rc = sodium_hex2bin(key.bytes_.data(), key.bytes_.size(), text.data(), text.size(),
                                nullptr, &decoded, nullptr);
  sodium_memzero(text.data(), text.size());
  if (rc != 0 || decoded != kSize) fail(path, "not hex: expected 64 characters 0-9 a-f");
  return key;
}

void write_new_key_file(const std::string& path, bool replace) {
  ensure_sodium();
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !std::filesystem::exists(parent, ec)) {
    std::filesystem::create_directories(parent, ec);
    if (ec) fail(path, "cannot create folder " + parent.string() + ": " + ec.message());
    std::filesystem::permissions(parent, std::filesystem::perms::owner_all, ec);
  }
  std::array<uint8_t, LabKey::kSize> bytes{};
  randombytes_buf(bytes.data(), bytes.size());
  std::string text(kHexSize + 1, '\0');
  sodium_bin2hex(text.data(), text.size(), bytes.data(), bytes.size());
  text.back() = '\n';  // bin2hex's terminating NUL becomes the newline
  sodium_memzero(bytes.data(), bytes.size());
  try {
    if (!replace) {
      create_exclusive(path, text);
    } else {
      const std::string temporary = path + ".new";
      ::unlink(temporary.c_str());  // a leftover of an interrupted run
      create_exclusive(temporary, text);
      if (std::rename(temporary.c_str(), path.c_str()) != 0) {
        const std::string why = errno_text();
        ::unlink(temporary.c_str());
        fail(path, "cannot replace: " + why);
      }
    }
  } catch (...) {
    sodium_memzero(text.data(), text.size());
    throw;
  }
  sodium_memzero(text.data(), text.size());
}

std::string default_key_path() {
  if (const char* p = std::getenv("SG_LAB_KEY"); p && *p) return p;
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.config/stereograsp/lab.key";
  throw LabKeyError("lab key: neither SG_LAB_KEY nor HOME is set; give --key PATH");
}

}  // namespace sg::auth
