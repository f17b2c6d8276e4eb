#include "common/bus.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "common/shutdown.hpp"

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

}  // namespace

class Bus::RawHandler {
 public:
  explicit RawHandler(std::function<void(const RawMessage&)> fn) : fn_(std::move(fn)) {}
  void handleMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    RawMessage raw;
    raw.info.channel = channel;
    raw.info.recv_utime = rbuf->recv_utime;
    raw.info.size = static_cast<int32_t>(rbuf->data_size);
    raw.data = static_cast<const uint8_t*>(rbuf->data);
    fn_(raw);
  }

 private:
  std::function<void(const RawMessage&)> fn_;
};

Bus::Bus(const std::string& url) : url_(url) {
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

Bus::~Bus() = default;

bool Bus::publish_raw(const std::string& channel, const void* data, int size) {
  if (lcm_->publish(channel, data, static_cast<unsigned>(size)) == 0) return true;
  ++publish_errors_;
  spdlog::warn("publish on {} failed ({} bytes): {}", channel, size, std::strerror(errno));
  return false;
}

void Bus::subscribe_raw(const std::string& channel_regex,
                        std::function<void(const RawMessage&)> handler) {
  handlers_.push_back(std::make_unique<RawHandler>(std::move(handler)));
  lcm_->subscribe(channel_regex, &RawHandler::handleMessage, handlers_.back().get());
}

bool Bus::handle(std::chrono::milliseconds timeout) {
  const int status = lcm_->handleTimeout(static_cast<int>(timeout.count()));
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
  while (!shutdown_requested() && keep_going() && !end_of_log_) handle(poll);
}

void Bus::report_decode_error(const ReceiveInfo& info, const char* type_name) {
  ++decode_errors_;
  // The first few in full, then one line in a thousand: a wrong publisher must not flood logs.
  if (decode_errors_ <= 10 || decode_errors_ % 1000 == 0) {
    spdlog::warn("{}: dropped a {}-byte message that is not a valid {} ({} so far)", info.channel,
                 info.size, type_name, decode_errors_);
  }
}

}  // namespace sg
