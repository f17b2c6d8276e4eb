#include "common/bus.hpp"

#include <arpa/inet.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <optional>

#include "common/clock.hpp"
#include "common/lcm_channel_filter.hpp"
#include "common/lcm_datagram.hpp"
#include "common/log_format.hpp"
#include "common/shutdown.hpp"
#include "common/udpm_socket.hpp"
#include "common/vouch_trailer.hpp"

namespace sg {
namespace {

/// Runs `fn` with the process's stderr sent to a temporary file and returns what was written
/// there: LCM reports a bad URL by printing, not by returning a reason.
template <class Fn>
std::string capture_stderr(Fn&& fn) {
  std::fflush(stderr);
  FILE* sink = std::tmpfile();
  const int saved = dup(STDERR_FILENO);
  if (sink == nullptr || saved < 0) {
    if (sink != nullptr) std::fclose(sink);
    if (saved >= 0) close(saved);
    fn();
    return {};
  }
  dup2(fileno(sink), STDERR_FILENO);
  fn();
  std::fflush(stderr);
  dup2(saved, STDERR_FILENO);
  close(saved);
  std::string text;
  std::rewind(sink);
  char chunk[512];
  size_t n = 0;
  while ((n = std::fread(chunk, 1, sizeof chunk, sink)) > 0) text.append(chunk, n);
  std::fclose(sink);
  return text;
}

/// LCM's complaint as one line: its first meaningful lines joined, the advice it prints for a
/// missing multicast route replaced by ours.
std::string one_line(const std::string& text) {
  if (text.find("multicast route") != std::string::npos) {
    return "no multicast route on this host (run scripts/multicast.sh, or use ttl=0 on a host "
           "with a network)";
  }
  std::string line;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string part = text.substr(start, end - start);
    start = end + 1;
    if (part.empty()) continue;
    if (!line.empty()) line += "; ";
    line += part;
  }
  return line;
}

/// The URL as the user knows it: as given, or where LCM's default came from.
std::string describe_url(const std::string& url) {
  std::string shown;
  const char* env = std::getenv("LCM_DEFAULT_URL");
  if (!url.empty()) {
    shown.append("'").append(url).append("'");
  } else if (env != nullptr) {
    shown.append("'").append(env).append("' (LCM_DEFAULT_URL)");
  } else {
    shown = "(LCM's default)";
  }
  return shown;
}

/// For a `file://` URL read by LCM's file provider: "" when the log is whole, else why not.
/// LCM's reader trusts every event length (common/log_format.hpp), so a damaged log is refused
/// here, before LCM opens it.
std::string damage_of_log_url(const std::string& url) {
  if (url.rfind("file://", 0) != 0) return {};
  const size_t query = url.find('?');
  const std::string options = query == std::string::npos ? "" : url.substr(query + 1);
  if (options.find("mode=w") != std::string::npos || options.find("mode=a") != std::string::npos)
    return {};
  const std::string path = url.substr(7, query == std::string::npos ? query : query - 7);
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return {};  // LCM says why it cannot open it
  std::string damage;
  if (fseeko(f, 0, SEEK_END) == 0) damage = log_format::first_damage(f, ftello(f));
  std::fclose(f);
  return damage;
}

}  // namespace

/// Called by LCM's C dispatch and by the bus's own socket: nothing may leave it by an exception.
class Bus::RawHandler {
 public:
  RawHandler(Bus& bus, std::function<void(const RawMessage&)> fn) : bus_(bus), fn_(std::move(fn)) {}
  void handleMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) noexcept {
    deliver(channel, rbuf->recv_utime, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size);
  }
  void deliver(const std::string& channel, int64_t recv_utime, const uint8_t* data,
               size_t size) noexcept {
    try {
      ++bus_.messages_received_;
      bus_.rates_.received(channel);
      size_t payload = size;
      if (!bus_.admit(channel, data, size, payload)) return;
      RawMessage raw;
      raw.info.channel = channel;
      raw.info.recv_utime = recv_utime;
      raw.info.size = static_cast<int32_t>(payload);
      raw.data = data;
      fn_(raw);
    } catch (const std::exception& e) {
      bus_.report_handler_error(channel, e.what());
    } catch (...) {
      bus_.report_handler_error(channel, "an exception that is not a std::exception");
    }
  }

 private:
  Bus& bus_;
  std::function<void(const RawMessage&)> fn_;
};

Bus::Bus(const std::string& url) : url_(url) {
  if (const std::string damage = damage_of_log_url(url_); !damage.empty()) {
    throw BusError("LCM URL '" + url_ + "': the log is damaged at " + damage +
                   "; LCM's reader cannot read it safely (sg-bus-check verify-log lists the "
                   "damage; sg-report reads around it)");
  }
  const std::string complaint = capture_stderr([&] { lcm_ = std::make_unique<lcm::LCM>(url_); });
  const std::string shown = describe_url(url_);
  if (!lcm_->good()) {
    throw BusError("cannot open LCM URL " + shown + ": " +
                   (complaint.empty() ? "LCM refused it" : one_line(complaint)));
  }
  if (!complaint.empty()) {  // e.g. "Warning: Invalid value for ttl": do not run half-right
    throw BusError("LCM URL " + shown + " is not valid: " + one_line(complaint));
  }
}

Bus::~Bus() {
  // A last word: a process that exits says so, so a watcher tells a stop from a crash.
  if (process_.empty() || state_ == stereograsp::process_status_t::STATE_STOPPING) return;
  try {
    set_state(stereograsp::process_status_t::STATE_STOPPING,
              shutdown_requested() ? "asked to stop" : "exiting");
  } catch (...) {  // nothing may leave a destructor
  }
}

bool Bus::publish_raw(const std::string& channel, const void* data, int size) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  buffer_.assign(bytes, bytes + std::max(size, 0));
  return send_buffer(channel);
}

bool Bus::send_buffer(const std::string& channel) {
  if (guard_) guard_->vouch(channel, buffer_);
  const size_t size = buffer_.size();
  last_handed_utime_ = now_utime();
  if (lcm_->publish(channel, buffer_.data(), static_cast<unsigned>(size)) == 0) {
    rates_.sent(channel);
    return true;
  }
  ++publish_errors_;
  spdlog::warn("publish on {} failed ({} bytes): {}", channel, size, std::strerror(errno));
  return false;
}

void Bus::subscribe_raw(const std::string& channel_regex,
                        std::function<void(const RawMessage&)> handler, int queue) {
  const std::string refused =
      "cannot hold " + std::to_string(queue) + " messages for '" + channel_regex + "'";
  if (queue < 1) throw BusError(refused);  // before subscribing: nothing is left half-made
  handlers_.push_back(std::make_unique<RawHandler>(*this, std::move(handler)));
  // LCM opens its receive socket at the first subscription; it is the one that appears. One bus
  // at a time, so that two in one process cannot take each other's.
  static std::mutex first_subscriptions;
  std::unique_lock<std::mutex> one_at_a_time(first_subscriptions, std::defer_lock);
  if (lcm_subscriptions_ == 0) one_at_a_time.lock();
  const std::vector<int> before = lcm_subscriptions_ == 0 ? lcm_sockets() : std::vector<int>{};
  lcm::Subscription* subscription =
      lcm_->subscribe(channel_regex, &RawHandler::handleMessage, handlers_.back().get());
  if (subscription == nullptr) throw BusError("cannot subscribe to '" + channel_regex + "'");
  if (subscription->setQueueCapacity(queue) != 0) {
    lcm_->unsubscribe(subscription);
    throw BusError(refused);
  }
  if (lcm_subscriptions_++ == 0) find_lcm_socket(before);
  if (is_plain_channel_name(channel_regex))
    lcm_channels_.push_back(channel_regex);
  else
    lcm_channels_any_ = true;
  filter_lcm_socket();
}

std::vector<int> Bus::lcm_sockets() const {
  std::optional<UdpmEndpoint> endpoint;
  try {
    endpoint = udpm_endpoint(url_);
  } catch (const std::invalid_argument&) {
    return {};  // LCM refused it in the constructor
  }
  return endpoint ? udp_sockets_bound_to(endpoint->port) : std::vector<int>{};
}

void Bus::find_lcm_socket(const std::vector<int>& before) {
  std::vector<int> appeared;
  for (const int fd : lcm_sockets())
    if (std::find(before.begin(), before.end(), fd) == before.end()) appeared.push_back(fd);
  if (appeared.size() == 1) lcm_socket_ = appeared.front();
}

void Bus::filter_lcm_socket() {
  if (lcm_socket_ < 0) return;
  if (lcm_channels_any_) {
    detach_lcm_channel_filter(lcm_socket_);
    lcm_filtered_ = false;
    return;
  }
  try {
    attach_lcm_channel_filter(lcm_socket_, lcm_channels_);
    lcm_filtered_ = true;
  } catch (const std::exception& e) {  // the filter only saves wake-ups; LCM reads on without
    spdlog::warn("bus {}: {}", url_, e.what());
    detach_lcm_channel_filter(lcm_socket_);
    lcm_filtered_ = false;
  }
}

/// The channels read on the bus's own socket (subscribe_direct).
struct Bus::Direct {
  explicit Direct(const UdpmEndpoint& endpoint) : socket(endpoint) {}
  UdpmSocket socket;
  LcmDatagramAssembler assembler;
  std::vector<std::pair<std::string, std::unique_ptr<RawHandler>>> channels;

  RawHandler* handler_of(std::string_view channel) const {
    for (const auto& [name, handler] : channels)
      if (name == channel) return handler.get();
    return nullptr;
  }
};

bool Bus::subscribe_direct_raw(const std::string& channel,
                               std::function<void(const RawMessage&)> handler, int queue) {
  std::optional<UdpmEndpoint> endpoint;
  try {
    endpoint = udpm_endpoint(url_);
  } catch (const std::invalid_argument& e) {
    throw BusError(e.what());
  }
  if (!endpoint) {
    subscribe_raw(channel, std::move(handler), queue);
    return false;
  }
  if (channel.empty() || channel.size() > kLcmMaxChannel)
    throw BusError("cannot read channel '" + channel + "' directly: not an LCM channel name");
  try {
    if (!direct_) direct_ = std::make_unique<Direct>(*endpoint);
  } catch (const std::runtime_error& e) {
    throw BusError(e.what());
  }
  if (direct_->handler_of(channel) != nullptr)
    throw BusError("channel '" + channel + "' is already read directly");
  direct_->channels.emplace_back(channel, std::make_unique<RawHandler>(*this, std::move(handler)));
  std::vector<std::string> names;
  for (const auto& [name, unused] : direct_->channels) names.push_back(name);
  try {
    attach_lcm_channel_filter(direct_->socket.fd(), names);
  } catch (const std::exception& e) {  // it reads every datagram then, and drops the others
    spdlog::warn("bus {}: {}", url_, e.what());
  }
  return true;
}

namespace {
/// "10.0.0.5:40123" from UdpmSocket's sender number.
std::string sender_name(uint64_t sender) {
  in_addr address{};
  address.s_addr = htonl(static_cast<uint32_t>(sender >> 16));
  char text[INET_ADDRSTRLEN] = "?";
  inet_ntop(AF_INET, &address, text, sizeof text);
  return std::string(text) + ":" + std::to_string(sender & 0xffff);
}
}  // namespace

bool Bus::drain_direct() {
  bool handled = false;
  UdpmSocket::Datagram d;
  // Bounded, so that a flood on the group cannot keep LCM's channels waiting for ever.
  for (int i = 0; i < 256 && direct_->socket.receive(d); ++i) {
    const auto wanted = [&](std::string_view c) { return direct_->handler_of(c) != nullptr; };
    const auto refused = [&](const std::string& why) {
      note_problem(++decode_errors_, "bus datagram from " + sender_name(d.sender) + ": " + why);
    };
    const auto message = direct_->assembler.add(d.sender, d.bytes, d.size, wanted, refused);
    if (!message) continue;
    const std::string channel(message->channel);
    ++dispatch_;
    direct_->handler_of(channel)->deliver(channel, d.recv_utime, message->data, message->size);
    handled = true;
  }
  return handled;
}

bool Bus::handle(std::chrono::microseconds timeout) {
  tick();
  timeout = std::max(timeout, std::chrono::microseconds(0));
  if (!direct_) {  // LCM waits in whole milliseconds: round up, never to a busy loop
    const auto ms = std::chrono::ceil<std::chrono::milliseconds>(timeout);
    return handle_lcm(static_cast<int>(std::min<int64_t>(ms.count(), INT32_MAX)));
  }
  // LCM's descriptor only when it has subscriptions: asking for it starts LCM's receive thread.
  const bool lcm_too = lcm_subscriptions_ > 0;
  pollfd fds[2] = {{direct_->socket.fd(), POLLIN, 0},
                   {lcm_too ? lcm_->getFileno() : -1, POLLIN, 0}};
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(timeout);
  const timespec wait{static_cast<time_t>(seconds.count()),
                      static_cast<long>((timeout - seconds).count() * 1000)};
  const int ready = ppoll(fds, lcm_too ? 2 : 1, &wait, nullptr);
  if (ready < 0) {
    if (errno == EINTR) return false;
    throw BusError(std::string("waiting for messages failed: ") + std::strerror(errno));
  }
  bool handled = false;
  try {
    if (fds[0].revents != 0) handled = drain_direct();
  } catch (const std::runtime_error& e) {
    throw BusError(e.what());
  }
  if (fds[1].revents != 0) handled = handle_lcm(0) || handled;
  return handled;
}

bool Bus::handle_lcm(int timeout_ms) {
  ++dispatch_;  // LCM dispatches one message a handle, to each subscription it matches
  in_lcm_handle_ = true;
  const int status = lcm_->handleTimeout(timeout_ms);
  in_lcm_handle_ = false;
  if (status > 0) return true;
  if (status == 0) return false;
  if (url_.rfind("file://", 0) == 0) {  // LCM 1.3.1 returns -1 at the end of a log
    end_of_log_ = true;
    return false;
  }
  if (errno == EINTR) return false;
  throw BusError("LCM failed while waiting for messages on " +
                 (url_.empty() ? std::string("the default URL") : url_));
}

void Bus::spin(const std::function<bool()>& keep_going, std::chrono::milliseconds poll) {
  spin(keep_going, [poll] { return std::chrono::microseconds(poll); });
}

void Bus::spin(const std::function<bool()>& keep_going,
               const std::function<std::chrono::microseconds()>& wait) {
  while (!shutdown_requested() && keep_going() && !end_of_log_) handle(wait());
  if (shutdown_requested() && !process_.empty())
    set_state(stereograsp::process_status_t::STATE_STOPPING, "asked to stop");
}

void Bus::note_problem(uint64_t count, const std::string& line) {
  last_problem_ = line;
  if (count <= 10 || count % 1000 == 0) spdlog::warn("{} ({} so far)", line, count);
}

void Bus::report_decode_error(const ReceiveInfo& info, const std::string& why) {
  note_problem(++decode_errors_,
               info.channel + ": dropped a " + std::to_string(info.size) + "-byte message: " + why);
}

bool Bus::admit(const std::string& channel, const uint8_t* data, size_t size, size_t& payload) {
  if (!guard_) {
    payload = vouched_payload_size(data, size);
    return true;
  }
  const bool same = in_lcm_handle_ && admitted_.dispatch == dispatch_ && admitted_.data == data &&
                    admitted_.size == size && admitted_.channel == channel;
  if (same) {  // the message LCM is handing to its next subscription
    payload = admitted_.payload;
    return admitted_.accepted;
  }
  const GuardResult r = guard_->check(channel, data, size, now_utime());
  admitted_ = {dispatch_, channel, data, size, r.accepted(), r.payload_size};
  if (!r.accepted()) report_unvouched(channel, r);
  payload = r.payload_size;
  return r.accepted();
}

void Bus::report_unvouched(const std::string& channel, const GuardResult& result) {
  UnvouchedKey key{channel.substr(0, 256), result.sender, result.verdict};
  key.channel.erase(std::find(key.channel.begin(), key.channel.end(), '\0'), key.channel.end());
  auto row = unvouched_.find(key);
  if (row == unvouched_.end() && unvouched_.size() >= kUnvouchedRows)
    row = unvouched_.try_emplace(UnvouchedKey{"(other)", "", GuardVerdict::kUnsigned}, 0).first;
  else if (row == unvouched_.end())
    row = unvouched_.emplace(std::move(key), 0).first;
  ++row->second;
  note_problem(++unvouched_inputs_, channel + ": refused, not vouched for (" +
                                        to_string(result.verdict) + "): " + result.reason);
}

void Bus::report_handler_error(const std::string& channel, const std::string& what) {
  note_problem(++handler_errors_, channel + ": handler failed: " + what);
}

void Bus::note_refused(const std::string& channel, const std::string& why) {
  note_problem(++refused_inputs_, channel + ": refused: " + why);
}

void Bus::announce(const std::string& process, int8_t state, const std::string& detail) {
  const bool first = process_.empty();
  process_ = process;
  char name[256] = {};
  host_ = gethostname(name, sizeof name - 1) == 0 ? name : "?";
  state_ = state;
  state_detail_ = detail;
  if (first) {
    start_utime_ = now_utime();
    clock_sync_ = std::make_unique<ClockSync>(process_ + "@" + host_ + ":" +
                                              std::to_string(static_cast<int32_t>(getpid())));
    // The exchange needs receive times on this process's clock, taken here as the status is
    // handled: a kernel timestamp is the kernel's clock (under libfaketime, or a simulated
    // clock, they differ: every exchange came out +-400 ms +-400 ms in the lab test), and LCM
    // 1.3.1's recv_utime is the kernel's for a datagram read into a fresh buffer but its own
    // clock's after one it discarded (lcm_udpm.c keeps the buffer, and its stamp, across
    // discarded datagrams): which one depended on whether another channel's datagram came
    // first, and with the channel filter none does.
    subscribe<stereograsp::process_status_t>(
        "PROCESS_STATUS", [this](const stereograsp::process_status_t& s, const ReceiveInfo&) {
          clock_sync_->receive(s, now_utime());
        });
  }
  next_status_ = {};
  tick();
}

void Bus::set_state(int8_t state, const std::string& detail) {
  if (state == state_ && detail == state_detail_) return;
  state_ = state;
  state_detail_ = detail;
  if (!process_.empty()) publish_status();
}

stereograsp::process_status_t Bus::process_status(int64_t utime) {
  stereograsp::process_status_t s{};
  s.utime = utime;
  s.process = process_;
  s.host = host_;
  s.pid = static_cast<int32_t>(getpid());
  s.messages_received = static_cast<int64_t>(messages_received_);
  s.decode_errors = static_cast<int64_t>(decode_errors_);
  s.handler_errors = static_cast<int64_t>(handler_errors_);
  s.refused_inputs = static_cast<int64_t>(refused_inputs_);
  s.publish_errors = static_cast<int64_t>(publish_errors_);
  s.last_problem = last_problem_.substr(0, 1000);
  s.last_problem.erase(std::find(s.last_problem.begin(), s.last_problem.end(), '\0'),
                       s.last_problem.end());  // a channel name may hold anything
  s.state = state_;
  s.state_detail = state_detail_.substr(0, 1000);
  s.start_utime = start_utime_;
  rates_.fill(
      s,
      std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count());
  for (std::string& c : s.channel) c.erase(std::find(c.begin(), c.end(), '\0'), c.end());
  if (clock_sync_) clock_sync_->fill(s);
  s.unvouched_inputs = static_cast<int64_t>(unvouched_inputs_);
  for (const auto& [key, count] : unvouched_) {
    s.unvouched_channel.push_back(key.channel);
    s.unvouched_sender.push_back(key.sender);
    s.unvouched_verdict.push_back(key.channel == "(other)" ? "" : to_string(key.verdict));
    s.unvouched_count.push_back(static_cast<int64_t>(count));
  }
  s.num_unvouched = static_cast<int32_t>(s.unvouched_channel.size());
  s.vouched_as = guard_ ? guard_->identity() : "";
  return s;
}

void Bus::tick() {
  if (process_.empty()) return;
  const auto now = std::chrono::steady_clock::now();
  if (now < next_status_) return;
  publish_status();
}

void Bus::publish_status() {
  next_status_ = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  publish("PROCESS_STATUS", process_status(now_utime()));
}

}  // namespace sg
