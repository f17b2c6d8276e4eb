#include "common/udpm_socket.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

#include "common/clock.hpp"

namespace sg {
namespace {

constexpr const char* kLcmDefaultUrl = "udpm://239.255.76.67:7667?ttl=0";

/// A non-negative integer that fills `text`, at most `max`; none otherwise.
std::optional<long long> whole_number(const std::string& text, long long max) {
  if (text.empty() || text.size() > 18 || text.find_first_not_of("0123456789") != text.npos)
    return std::nullopt;
  const long long value = std::stoll(text);
  if (value > max) return std::nullopt;
  return value;
}

void read_network(const std::string& network, UdpmEndpoint& e, const std::string& url) {
  if (network.empty()) return;
  const size_t colon = network.find(':');
  e.group = network.substr(0, colon);
  in_addr address{};
  if (inet_pton(AF_INET, e.group.c_str(), &address) != 1)
    throw std::invalid_argument("LCM URL '" + url + "': '" + e.group + "' is not an IPv4 address");
  if (colon == std::string::npos) return;
  const auto port = whole_number(network.substr(colon + 1), 65535);
  if (!port || *port == 0)
    throw std::invalid_argument("LCM URL '" + url + "': '" + network.substr(colon + 1) +
                                "' is not a port");
  e.port = static_cast<uint16_t>(*port);
}

void read_options(const std::string& options, UdpmEndpoint& e, const std::string& url) {
  size_t start = 0;
  while (start < options.size()) {
    size_t end = options.find('&', start);
    if (end == std::string::npos) end = options.size();
    const std::string option = options.substr(start, end - start);
    start = end + 1;
    if (option.rfind("recv_buf_size=", 0) != 0) continue;  // ttl, ...: the sender's business
    const auto bytes = whole_number(option.substr(14), 1 << 30);
    if (!bytes)
      throw std::invalid_argument("LCM URL '" + url + "': recv_buf_size '" + option.substr(14) +
                                  "' is not a size in bytes");
    e.recv_buf_size = static_cast<int>(*bytes);
  }
}

int64_t kernel_utime(msghdr& message) {
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMP) {
      timeval tv;
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      return int64_t{tv.tv_sec} * 1000000 + tv.tv_usec;
    }
  }
  return now_utime();  // no timestamp: as close as this process can tell
}

}  // namespace

std::optional<UdpmEndpoint> udpm_endpoint(const std::string& url) {
  const char* env = std::getenv("LCM_DEFAULT_URL");
  const std::string given = !url.empty() ? url : (env != nullptr && *env ? env : kLcmDefaultUrl);
  const size_t scheme = given.find("://");
  const std::string provider = scheme == std::string::npos ? given : given.substr(0, scheme);
  if (provider != "udpm") return std::nullopt;
  const std::string rest = scheme == std::string::npos ? "" : given.substr(scheme + 3);
  const size_t query = rest.find('?');
  UdpmEndpoint e;
  read_network(rest.substr(0, query), e, given);
  if (query != std::string::npos) read_options(rest.substr(query + 1), e, given);
  return e;
}

UdpmSocket::UdpmSocket(const UdpmEndpoint& e) : buffer_(65536) {
  const std::string where = e.group + ":" + std::to_string(e.port);
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0)
    throw std::runtime_error("cannot open a socket for " + where + ": " + std::strerror(errno));
  const int on = 1;
  sockaddr_in at{};
  at.sin_family = AF_INET, at.sin_port = htons(e.port), at.sin_addr.s_addr = htonl(INADDR_ANY);
  ip_mreq join{};
  inet_pton(AF_INET, e.group.c_str(), &join.imr_multiaddr);
  join.imr_interface.s_addr = htonl(INADDR_ANY);
  const char* failed = nullptr;
  if (setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on) != 0)
    failed = "SO_REUSEADDR";
  else if (setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on) != 0)
    failed = "SO_TIMESTAMP";
  else if (e.recv_buf_size > 0 &&
           setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &e.recv_buf_size, sizeof e.recv_buf_size) != 0)
    failed = "SO_RCVBUF";
  else if (bind(fd_, reinterpret_cast<sockaddr*>(&at), sizeof at) != 0)
    failed = "bind";
  else if (setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &join, sizeof join) != 0)
    failed = "joining the group (no multicast route? scripts/multicast.sh)";
  if (failed != nullptr) {
    const std::string reason = std::strerror(errno);
    close(fd_);
    throw std::runtime_error("cannot read LCM bus " + where + ": " + failed + ": " + reason);
  }
}

UdpmSocket::~UdpmSocket() {
  if (fd_ >= 0) close(fd_);
}

bool UdpmSocket::receive(Datagram& d) {
  sockaddr_in from{};
  iovec iov{buffer_.data(), buffer_.size()};
  alignas(cmsghdr) char control[128];
  msghdr message{};
  message.msg_name = &from, message.msg_namelen = sizeof from;
  message.msg_iov = &iov, message.msg_iovlen = 1;
  message.msg_control = control, message.msg_controllen = sizeof control;
  const ssize_t n = recvmsg(fd_, &message, MSG_DONTWAIT);
  if (n < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return false;
    throw std::runtime_error(std::string("reading the LCM bus failed: ") + std::strerror(errno));
  }
  d.sender = (uint64_t{ntohl(from.sin_addr.s_addr)} << 16) | ntohs(from.sin_port);
  d.recv_utime = kernel_utime(message);
  d.bytes = buffer_.data();
  d.size = static_cast<size_t>(n);
  return true;
}

}  // namespace sg
