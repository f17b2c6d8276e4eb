// This machine's floor under sg-vision's latency (issue 19): how long a datagram waits between
// the kernel's receive timestamp and the code that reads it, with nothing else to do.
//   - a UDP multicast socket read by a thread blocked in recvmsg (SO_TIMESTAMP, as LCM stamps
//     recv_utime);
//   - LCM 1.3.1's UDP multicast provider, a handler that only reads rbuf->recv_utime: LCM's
//     receive thread, its pipe to the thread in lcm_handle, the dispatch;
//   - sg::Bus::subscribe_direct, as sg-vision reads its camera channels: the bus's own socket on
//     the group, read in the thread that spins, an empty handler.
//   - the first again with a second socket on the group read by another thread (what LCM's
//     receive thread is beside a bus's own socket, in sg-vision for PROCESS_STATUS): on a 2-vCPU
//     machine whose idle vCPU is slow to wake, p99 66-91 us alone, about 3 ms with it.
// sg-vision's "of which LCM's delivery" is the second with a real handler around it; a p99 here
// above sg-vision's goal (1.5 ms) is the platform's, not the program's.
//
//   scripts/multicast.sh run build/bin/delivery_floor [--count 1000] [--size 40000]
//       [--rate 40] [--realtime-priority 50]

#include <arpa/inet.h>
#include <lcm/lcm.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/bus.hpp"
#include "common/clock.hpp"
#include "common/latency_record.hpp"
#include "common/realtime.hpp"

namespace {

constexpr const char* kGroup = "239.255.76.67";

struct Settings {
  int count = 1000;
  int size = 40000;  // about a 640x480 JPEG at quality 90
  double rate = 40;  // two cameras at 20 Hz
  std::string url = "udpm://239.255.76.67:7962?ttl=0&recv_buf_size=4194304";
};

/// Calls `send(i)` `count` times at `rate` a second, from its own thread.
template <class Send>
std::thread paced(const Settings& s, Send send) {
  return std::thread([&s, send] {
    const auto period = std::chrono::duration<double>(1.0 / s.rate);
    auto next = std::chrono::steady_clock::now();
    for (int i = 0; i < s.count; ++i) {
      next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
      std::this_thread::sleep_until(next);
      send(i);
    }
  });
}

/// A UDP socket in multicast group 239.255.76.67 (LCM's), port `port`, as LCM opens its own.
int multicast_socket(uint16_t port) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) throw std::runtime_error("socket() failed");
  const int on = 1, buffer = 4 << 20;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on);
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
  const timeval patience{2, 0};  // a lost datagram ends the run rather than blocking it forever
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &patience, sizeof patience);
  sockaddr_in at{};
  at.sin_family = AF_INET, at.sin_port = htons(port), at.sin_addr.s_addr = htonl(INADDR_ANY);
  ip_mreq join{};
  join.imr_multiaddr.s_addr = inet_addr(kGroup);
  join.imr_interface.s_addr = htonl(INADDR_ANY);
  if (bind(fd, reinterpret_cast<sockaddr*>(&at), sizeof at) != 0 ||
      setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &join, sizeof join) != 0)
    throw std::runtime_error(std::string("cannot join ") + kGroup + " (scripts/multicast.sh run)");
  return fd;
}

/// The kernel's receive time of the datagram recvmsg just read (SCM_TIMESTAMP), in us.
int64_t kernel_utime(msghdr& msg) {
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMP) {
      timeval tv;
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      return int64_t{tv.tv_sec} * 1000000 + tv.tv_usec;
    }
  }
  return 0;
}

/// A plain UDP multicast socket: kernel timestamp -> recvmsg returns in a blocked reader. With
/// `second_reader`, another socket on the group reads every datagram too, in its own thread, as
/// LCM's receive thread does in a process that also reads a channel directly.
sg::LatencyRecord socket_floor(const Settings& s, bool second_reader = false) {
  constexpr uint16_t kPort = 7963;
  const int rx = multicast_socket(kPort), tx = socket(AF_INET, SOCK_DGRAM, 0);
  std::atomic<bool> done{false};
  std::thread other;
  if (second_reader) {
    other = std::thread([&done, fd = multicast_socket(kPort)] {
      std::vector<char> bytes(65536);
      while (!done.load()) recv(fd, bytes.data(), bytes.size(), 0);  // SO_RCVTIMEO: 2 s at most
      close(fd);
    });
  }
  const unsigned char ttl = 0;
  setsockopt(tx, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
  sockaddr_in to{};
  to.sin_family = AF_INET, to.sin_port = htons(kPort), to.sin_addr.s_addr = inet_addr(kGroup);
  const std::vector<char> payload(static_cast<size_t>(std::min(s.size, 65000)), 'x');
  std::thread sender = paced(s, [&](int) {
    sendto(tx, payload.data(), payload.size(), 0, reinterpret_cast<const sockaddr*>(&to),
           sizeof to);
  });
  sg::LatencyRecord latency;
  std::vector<char> buf(65536);
  alignas(cmsghdr) char control[256];
  for (int i = 0; i < s.count; ++i) {
    iovec iov{buf.data(), buf.size()};
    msghdr msg{};
    msg.msg_iov = &iov, msg.msg_iovlen = 1;
    msg.msg_control = control, msg.msg_controllen = sizeof control;
    if (recvmsg(rx, &msg, 0) < 0) break;
    const int64_t stamped = kernel_utime(msg);
    if (stamped != 0) latency.add(sg::now_utime() - stamped);
  }
  sender.join();
  done = true;
  if (other.joinable()) other.join();
  close(rx), close(tx);
  return latency;
}

/// LCM: kernel timestamp (recv_utime) -> the handler, which does nothing else.
sg::LatencyRecord lcm_floor(const Settings& s) {
  lcm_t* rx = lcm_create(s.url.c_str());
  lcm_t* tx = lcm_create(s.url.c_str());
  if (!rx || !tx) throw std::runtime_error("cannot open LCM at " + s.url);
  sg::LatencyRecord latency;
  auto handler = [](const lcm_recv_buf_t* rbuf, const char*, void* user) {
    static_cast<sg::LatencyRecord*>(user)->add(sg::now_utime() - rbuf->recv_utime);
  };
  lcm_subscribe(rx, "DELIVERY_FLOOR", handler, &latency);
  const std::vector<char> payload(static_cast<size_t>(s.size), 'x');
  std::thread sender = paced(s, [&](int) {
    lcm_publish(tx, "DELIVERY_FLOOR", payload.data(), static_cast<unsigned>(payload.size()));
  });
  const int64_t end = sg::now_utime() + static_cast<int64_t>((s.count / s.rate + 2) * 1e6);
  while (latency.count() < static_cast<uint64_t>(s.count) && sg::now_utime() < end)
    lcm_handle_timeout(rx, 100);
  sender.join();
  lcm_destroy(tx), lcm_destroy(rx);
  return latency;
}

/// sg::Bus::subscribe_direct (sg-vision's camera channels): the bus's own socket read in the
/// thread that calls spin(), LCM's receive thread running beside it; the handler does nothing
/// else. The product's path, with the raw bytes' decoding as the only work.
sg::LatencyRecord direct_floor(const Settings& s) {
  sg::Bus rx(s.url), tx(s.url);
  sg::LatencyRecord latency;
  rx.subscribe_direct_raw("DELIVERY_FLOOR", [&](const sg::RawMessage& m) {
    latency.add(sg::now_utime() - m.info.recv_utime);
  });
  const std::vector<uint8_t> payload(static_cast<size_t>(s.size), 'x');
  std::thread sender = paced(s, [&](int) {
    tx.publish_raw("DELIVERY_FLOOR", payload.data(), static_cast<int>(payload.size()));
  });
  const int64_t end = sg::now_utime() + static_cast<int64_t>((s.count / s.rate + 2) * 1e6);
  rx.spin(
      [&] { return latency.count() < static_cast<uint64_t>(s.count) && sg::now_utime() < end; });
  sender.join();
  return latency;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "This machine's floor under sg-vision's latency: kernel receive timestamp -> the reading "
      "code, through a plain UDP socket and through LCM with an empty handler."};
  Settings s;
  int realtime = 0;
  app.add_option("--count", s.count, "messages a run")->check(CLI::Range(10, 1000000));
  app.add_option("--size", s.size, "bytes a message (a JPEG frame: about 40000)")
      ->check(CLI::Range(1, 4000000));
  app.add_option("--rate", s.rate, "messages a second")->check(CLI::Range(1.0, 1000.0));
  app.add_option("--lcm-url", s.url, "the bus (this host only: ttl=0)");
  app.add_option("--realtime-priority", realtime, "SCHED_FIFO for this process (0: off)")
      ->check(CLI::Range(0, 99));
  CLI11_PARSE(app, argc, argv);
  try {
    if (const std::string e = sg::enter_realtime(realtime); !e.empty())
      std::fprintf(stderr, "%s\n", e.c_str());
    std::printf(
        "%d messages of %d bytes at %.0f a second, %s\n", s.count, s.size, s.rate,
        realtime ? ("SCHED_FIFO " + std::to_string(realtime)).c_str() : "the ordinary scheduler");
    std::printf("  UDP socket, blocked reader:  %s\n", socket_floor(s).summary().c_str());
    std::printf("  ... a second reader beside:  %s\n", socket_floor(s, true).summary().c_str());
    std::printf("  LCM, empty handler:          %s\n", lcm_floor(s).summary().c_str());
    std::printf("  sg::Bus, read directly:      %s\n", direct_floor(s).summary().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "delivery_floor: %s\n", e.what());
    return 1;
  }
  return 0;
}
