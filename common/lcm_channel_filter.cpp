#include "common/lcm_channel_filter.hpp"

#include <arpa/inet.h>
#include <dirent.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "common/lcm_datagram.hpp"

namespace sg {
namespace {

constexpr uint32_t kUdpHeader = 8;                      // where the UDP payload starts
constexpr uint32_t kShortChannel = kUdpHeader + 8;      // after magic and sequence
constexpr uint32_t kFragmentNumber = kUdpHeader + 16;   // after magic, sequence, size, offset
constexpr uint32_t kFragmentChannel = kUdpHeader + 20;  // after the fragment counts
constexpr uint32_t kPass = 0xffffffff;                  // the whole datagram
constexpr uint32_t kDrop = 0;

/// A classic BPF program, built forwards as its jumps go: jumps name a label placed later.
class Program {
 public:
  void op(uint16_t code, uint32_t k = 0) { code_.push_back(BPF_STMT(code, k)); }
  /// If (A `test` k) go to `if_true`, else to `if_false` (-1: the next instruction).
  void jump(uint16_t test, uint32_t k, int if_true, int if_false = -1) {
    fixups_.push_back({code_.size(), if_true, if_false, false});
    code_.push_back(BPF_JUMP(BPF_JMP | test, k, 0, 0));
  }
  void go(int label) {
    fixups_.push_back({code_.size(), label, -1, true});
    op(BPF_JMP | BPF_JA);
  }
  /// If (A `test` k) return `value`.
  void when(uint16_t test, uint32_t k, uint32_t value) {
    code_.push_back(BPF_JUMP(BPF_JMP | test, k, 0, 1));
    op(BPF_RET | BPF_K, value);
  }
  /// Unless (A `test` k) return `value`: the guard before a load that could run past the
  /// datagram (a load out of bounds would end the whole program with a drop).
  void unless(uint16_t test, uint32_t k, uint32_t value) {
    code_.push_back(BPF_JUMP(BPF_JMP | test, k, 1, 0));
    op(BPF_RET | BPF_K, value);
  }
  int label() {
    labels_.push_back(SIZE_MAX);
    return static_cast<int>(labels_.size() - 1);
  }
  void place(int label) { labels_[static_cast<size_t>(label)] = code_.size(); }

  std::vector<sock_filter> finish() {
    for (const Fixup& f : fixups_) {
      if (f.always) {
        code_[f.at].k = static_cast<uint32_t>(distance(f.at, f.if_true));
        continue;
      }
      code_[f.at].jt = static_cast<uint8_t>(distance(f.at, f.if_true));
      code_[f.at].jf = static_cast<uint8_t>(distance(f.at, f.if_false));
      if (code_[f.at].jt != distance(f.at, f.if_true) ||
          code_[f.at].jf != distance(f.at, f.if_false))
        throw std::logic_error("LCM channel filter: a jump beyond classic BPF's 255");
    }
    return code_;
  }

 private:
  struct Fixup {
    size_t at;
    int if_true, if_false;
    bool always;
  };
  size_t distance(size_t at, int label) const {
    if (label < 0) return 0;
    const size_t to = labels_[static_cast<size_t>(label)];
    if (to == SIZE_MAX || to <= at) throw std::logic_error("LCM channel filter: a bad jump");
    return to - at - 1;
  }
  std::vector<sock_filter> code_;
  std::vector<size_t> labels_;
  std::vector<Fixup> fixups_;
};

/// The header: X = where the channel starts, in a short message or a first fragment, and M[0] =
/// the bytes from there on; everything else (not LCM's, cut short, a later fragment) passes.
void read_header(Program& p) {
  const int fragment = p.label(), channel = p.label();
  p.op(BPF_LD | BPF_W | BPF_LEN);
  p.unless(BPF_JGE | BPF_K, kUdpHeader + 4, kPass);  // no magic: the reader refuses it
  p.op(BPF_LD | BPF_W | BPF_ABS, kUdpHeader);
  p.jump(BPF_JEQ | BPF_K, kLcmMagicLong, fragment);
  p.unless(BPF_JEQ | BPF_K, kLcmMagicShort, kPass);  // not LCM's: the reader refuses it
  p.op(BPF_LDX | BPF_W | BPF_IMM, kShortChannel);
  p.go(channel);
  p.place(fragment);
  p.op(BPF_LD | BPF_W | BPF_LEN);
  p.unless(BPF_JGE | BPF_K, kFragmentNumber + 2, kPass);
  p.op(BPF_LD | BPF_H | BPF_ABS, kFragmentNumber);
  p.unless(BPF_JEQ | BPF_K, 0, kPass);  // a later fragment: it names no channel
  p.op(BPF_LDX | BPF_W | BPF_IMM, kFragmentChannel);
  p.place(channel);
  p.op(BPF_LD | BPF_W | BPF_LEN);
  p.unless(BPF_JGT | BPF_X, 0, kPass);  // no channel byte: the reader refuses it
  p.op(BPF_ALU | BPF_SUB | BPF_X);
  p.op(BPF_ST, 0);
}

/// Passes the datagram when `name` and its NUL are at X (compared in words, halves and bytes);
/// goes on past the block otherwise.
void pass_name(Program& p, const std::string& name) {
  std::string bytes = name;
  bytes.push_back('\0');
  const int next = p.label();
  p.op(BPF_LD | BPF_MEM, 0);
  p.jump(BPF_JGE | BPF_K, static_cast<uint32_t>(bytes.size()), -1, next);
  for (uint32_t at = 0; at < bytes.size();) {
    const size_t left = bytes.size() - at;
    const uint32_t width = left >= 4 ? 4 : left >= 2 ? 2 : 1;
    uint32_t value = 0;
    for (uint32_t i = 0; i < width; ++i) value = (value << 8) | static_cast<uint8_t>(bytes[at + i]);
    p.op(BPF_LD | (width == 4 ? BPF_W : width == 2 ? BPF_H : BPF_B) | BPF_IND, at);
    p.jump(BPF_JEQ | BPF_K, value, -1, next);
    at += width;
  }
  p.op(BPF_RET | BPF_K, kPass);
  p.place(next);
}

/// No wanted name is there: drops the datagram when a name ends (its NUL) within LCM's 63 bytes
/// and the datagram, a well-formed start of another channel's message; passes it otherwise, for
/// the reader to refuse (a name cut short, too long or empty).
void drop_other_channel(Program& p) {
  p.op(BPF_LD | BPF_B | BPF_IND, 0);
  p.when(BPF_JEQ | BPF_K, 0, kPass);  // an empty name
  for (uint32_t i = 1; i <= kLcmMaxChannel; ++i) {
    p.op(BPF_LD | BPF_MEM, 0);
    p.unless(BPF_JGT | BPF_K, i, kPass);  // the datagram ends before the NUL
    p.op(BPF_LD | BPF_B | BPF_IND, i);
    p.when(BPF_JEQ | BPF_K, 0, kDrop);
  }
  p.op(BPF_RET | BPF_K, kPass);  // longer than LCM allows
}

}  // namespace

std::vector<sock_filter> lcm_channel_filter(const std::vector<std::string>& channels) {
  for (const std::string& c : channels)
    if (c.empty() || c.size() > kLcmMaxChannel)
      throw std::invalid_argument("'" + c + "' is not an LCM channel name (1 to 63 bytes)");
  Program p;
  read_header(p);
  for (const std::string& c : channels) pass_name(p, c);
  drop_other_channel(p);
  std::vector<sock_filter> program = p.finish();
  if (program.size() > BPF_MAXINSNS)
    throw std::invalid_argument("too many channels for one socket filter (" +
                                std::to_string(channels.size()) + ")");
  return program;
}

void attach_lcm_channel_filter(int fd, const std::vector<std::string>& channels) {
  std::vector<sock_filter> program = lcm_channel_filter(channels);
  const sock_fprog fprog{static_cast<unsigned short>(program.size()), program.data()};
  if (setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &fprog, sizeof fprog) != 0)
    throw std::runtime_error(std::string("cannot attach the LCM channel filter: ") +
                             std::strerror(errno));
}

bool detach_lcm_channel_filter(int fd) {
  int unused = 0;
  return setsockopt(fd, SOL_SOCKET, SO_DETACH_FILTER, &unused, sizeof unused) == 0;
}

std::vector<int> udp_sockets_bound_to(uint16_t port) {
  std::vector<int> found;
  DIR* fds = opendir("/proc/self/fd");
  if (fds == nullptr) return found;
  while (const dirent* entry = readdir(fds)) {
    char* end = nullptr;
    const long fd = std::strtol(entry->d_name, &end, 10);
    if (end == entry->d_name || *end != '\0' || fd == dirfd(fds)) continue;
    int type = 0;
    socklen_t type_size = sizeof type;
    sockaddr_in address{};
    socklen_t address_size = sizeof address;
    if (getsockopt(static_cast<int>(fd), SOL_SOCKET, SO_TYPE, &type, &type_size) != 0 ||
        type != SOCK_DGRAM ||
        getsockname(static_cast<int>(fd), reinterpret_cast<sockaddr*>(&address), &address_size) !=
            0 ||
        address.sin_family != AF_INET || ntohs(address.sin_port) != port)
      continue;
    found.push_back(static_cast<int>(fd));
  }
  closedir(fds);
  return found;
}

bool is_plain_channel_name(const std::string& regex) {
  if (regex.empty() || regex.size() > kLcmMaxChannel) return false;
  for (const char c : regex) {
    const bool plain = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                       c == '_' || c == '-' || c == '/' || c == ':';
    if (!plain) return false;
  }
  return true;
}

}  // namespace sg
