#pragma once

/// A socket of a process's own on an LCM `udpm://` bus's multicast group: the datagrams every
/// LCM process on the group receives, read where the caller wants them (Bus::subscribe_direct
/// reads camera frames in the thread that tracks, without LCM's receive thread; issue 19).
///
///     const std::optional<sg::UdpmEndpoint> bus = sg::udpm_endpoint(url);  // none: not udpm
///     sg::UdpmSocket socket(*bus);
///     sg::UdpmSocket::Datagram d;
///     while (socket.receive(d)) use(d.sender, d.bytes, d.size, d.recv_utime);  // until empty
///
/// Opened as LCM opens its own receive socket (lcm_udpm.c): bound to the group's port on every
/// interface with SO_REUSEADDR, so it and the LCM processes on the host each get every datagram;
/// a member of the group; the kernel's receive time of each datagram (SO_TIMESTAMP, LCM's
/// `recv_utime`); the receive buffer the URL's `recv_buf_size` asks for.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sg {

/// Where a `udpm://` bus is.
struct UdpmEndpoint {
  std::string group = "239.255.76.67";  ///< LCM's default multicast group
  uint16_t port = 7667;                 ///< and port
  int recv_buf_size = 0;                ///< SO_RCVBUF to ask for; 0: the kernel's default
};

/// The endpoint of LCM URL `url` ("" for LCM_DEFAULT_URL, else LCM's default
/// udpm://239.255.76.67:7667); none when it names another provider (file://, memq://, ...).
/// Throws std::invalid_argument for a udpm URL whose address, port or recv_buf_size LCM would
/// not take either.
std::optional<UdpmEndpoint> udpm_endpoint(const std::string& url);

class UdpmSocket {
 public:
  /// Opens and joins; throws std::runtime_error, one line naming the group and the reason.
  explicit UdpmSocket(const UdpmEndpoint& endpoint);
  ~UdpmSocket();
  UdpmSocket(const UdpmSocket&) = delete;
  UdpmSocket& operator=(const UdpmSocket&) = delete;

  /// For poll(): readable when a datagram waits.
  int fd() const { return fd_; }

  struct Datagram {
    uint64_t sender = 0;             ///< the sender's IPv4 address and port, one number
    int64_t recv_utime = 0;          ///< the kernel's receive time (us since the Unix epoch)
    const uint8_t* bytes = nullptr;  ///< valid until the next receive()
    size_t size = 0;
  };

  /// Reads one waiting datagram without blocking; false when none waits. Throws
  /// std::runtime_error when the socket fails.
  bool receive(Datagram& d);

 private:
  int fd_ = -1;
  std::vector<uint8_t> buffer_;
};

}  // namespace sg
