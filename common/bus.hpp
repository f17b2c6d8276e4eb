#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/channel_rates.hpp"
#include "common/clock_sync.hpp"
#include "common/message_guard.hpp"
#include "common/safe_decode.hpp"
#include "stereograsp/process_status_t.hpp"

namespace sg {

/// The bus could not be opened or used; the message is one line that names the URL.
class BusError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What arrived with a message, besides its contents.
struct ReceiveInfo {
  std::string channel;
  int64_t recv_utime = 0;  ///< when LCM received it (microseconds since the Unix epoch)
  int32_t size = 0;        ///< encoded size in bytes
};

/// A raw, undecoded message (for loggers and tools that handle any type).
struct RawMessage {
  ReceiveInfo info;
  const uint8_t* data = nullptr;
};

/// How many messages LCM holds for one subscription while its handler is busy; it drops what
/// comes beyond that without a word (lcm_subscription_set_queue_capacity). LCM's own default is
/// 30: 0.3 s of a 100 Hz stream, so a process that stalls that long (a loaded machine, a replay
/// with `lcm-logplayer -s 10`) silently lost samples of a time series.
///
/// kQueueEverySample is the default: 256 messages, a minute of the paper's 4 Hz and 2.5 s at
/// 100 Hz. A message of one datagram queues in LCM's receive ring (1 MB in LCM's udpm source),
/// one of many fragments in a heap buffer of its size: a stalled handler holds at most `queue` of
/// those (integration_hostile_bus_test's floods stay within its memory bound). kQueueFrames is for
/// camera images: LCM's 30, a second of video, already some MB (each a separate allocation), and a
/// frame older than that is not worth processing.
inline constexpr int kQueueEverySample = 256;
inline constexpr int kQueueFrames = 30;

/// The LCM bus every process talks through: typed publish and subscribe over `lcm::LCM`, with
/// clear errors where LCM itself only prints or returns a code.
///
///     sg::Bus bus(options.lcm_url);                       // "" = LCM's default (LCM_DEFAULT_URL)
///     bus.subscribe<stereograsp::point3_t>("OBJECT_POSITION",
///         [&](const stereograsp::point3_t& p, const sg::ReceiveInfo&) { predictor.add(p); });
///     bus.publish("OBJECT_TRAJECTORY", trajectory);
///     bus.spin();                                         // until SIGINT or SIGTERM
///
/// No message can crash or exhaust the process. Every message is checked against its type before
/// LCM's decoder sees it (sg::safe_decode: each length it claims within the bytes received and the
/// type's bound); one that does not decode as the subscribed type (another type on the channel, a
/// wrong size, a bad length, trailing bytes) is counted in decode_errors() and logged with its
/// channel and the reason; the handler is not called. Whatever a handler throws is caught here,
/// before it can unwind through LCM's C dispatch, counted in handler_errors() and logged; the bus
/// goes on serving. A program that announce()s itself publishes these counts on PROCESS_STATUS
/// once a second, with the refusals it counts itself (note_refused()).
class Bus {
 public:
  /// Opens the bus; throws BusError when LCM cannot use `url` (unknown provider, bad address,
  /// no multicast route, invalid option), with LCM's own complaint folded into one line.
  explicit Bus(const std::string& url = "");
  ~Bus();
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;

  /// The URL as given ("" for LCM's default).
  const std::string& url() const { return url_; }

  /// From now on, vouches for everything this bus publishes with `guard` and hands its handlers
  /// only what `guard` accepts, the trailer taken off (sg::MessageGuard). Refusals are counted
  /// per channel, claimed sender and verdict (unvouched_inputs(), PROCESS_STATUS), logged like
  /// decode errors, and never reach a handler. Without a guard the bus believes everything and
  /// strips any well-formed trailer before decoding. Set it before subscribing or publishing.
  void set_guard(std::shared_ptr<MessageGuard> guard) { guard_ = std::move(guard); }
  const MessageGuard* guard() const { return guard_.get(); }

  /// Encodes, vouches (with a guard) and publishes; returns false (and logs, and counts) when
  /// LCM could not send.
  template <class Message>
  bool publish(const std::string& channel, const Message& message) {
    const int size = message.getEncodedSize();
    buffer_.resize(static_cast<size_t>(size));
    if (message.encode(buffer_.data(), 0, size) != size) {
      throw BusError("cannot encode " + std::string(Message::getTypeName()) + " for channel " +
                     channel);
    }
    return send_buffer(channel);
  }

  /// Publishes bytes as they are, followed by the guard's trailer when the bus has a guard
  /// (tools and tests).
  bool publish_raw(const std::string& channel, const void* data, int size);

  /// Calls `handler` with each message on channels matching `channel_regex` that decodes as
  /// Message, exactly and completely.
  /// LCM holds up to `queue` of them while the handler is busy (kQueueEverySample).
  template <class Message>
  void subscribe(const std::string& channel_regex,
                 std::function<void(const Message&, const ReceiveInfo&)> handler,
                 int queue = kQueueEverySample) {
    subscribe_raw(channel_regex, decoding<Message>(std::move(handler)), queue);
  }

  /// Like subscribe(), for a stream whose latency matters (camera frames, issue 19). On a
  /// `udpm://` bus the messages on `channel` (a name, not a pattern) are read from a socket of
  /// the bus's own on its multicast group (sg::UdpmSocket, sg::LcmDatagramAssembler), in the
  /// thread that calls handle() or spin(): LCM's receive thread and its hand-off to that thread
  /// (a p99 of 3 ms on the lab's virtual machine, docs/performance.md) are not on their way.
  /// They are decoded, checked and counted as subscribe()'s are; a datagram that breaks LCM's
  /// format, and a message that lost a fragment, count as decode errors. No LCM subscription
  /// may also match `channel` (it would be delivered twice). On another provider (file://,
  /// memq://) this is subscribe(channel, handler, queue). Returns true when read directly.
  template <class Message>
  bool subscribe_direct(const std::string& channel,
                        std::function<void(const Message&, const ReceiveInfo&)> handler,
                        int queue = kQueueEverySample) {
    return subscribe_direct_raw(channel, decoding<Message>(std::move(handler)), queue);
  }

  /// subscribe_direct() for undecoded messages.
  bool subscribe_direct_raw(const std::string& channel,
                            std::function<void(const RawMessage&)> handler,
                            int queue = kQueueEverySample);

  /// Calls `handler` with every message on matching channels, undecoded. What it throws is
  /// caught and counted like a typed handler's. LCM holds up to `queue` of them while the
  /// handler is busy.
  void subscribe_raw(const std::string& channel_regex,
                     std::function<void(const RawMessage&)> handler, int queue = kQueueEverySample);

  /// Waits up to `timeout` (to the microsecond on a bus that reads directly, else rounded up to
  /// LCM's milliseconds) for one message and dispatches it (with subscribe_direct(): LCM's
  /// next message and every datagram waiting on the bus's own socket). Returns true when a
  /// message was handled, false on time-out (or an interrupting signal); throws BusError when
  /// LCM (or the bus's socket) fails,
  /// and, on a `file://` URL, returns false at the end of the log (see end_of_log()).
  bool handle(std::chrono::microseconds timeout);

  /// Dispatches messages until shutdown is requested (SIGINT, SIGTERM) or `keep_going` returns
  /// false; checks both at least every `poll`.
  void spin(
      const std::function<bool()>& keep_going = [] { return true; },
      std::chrono::milliseconds poll = std::chrono::milliseconds(100));

  /// spin() that asks `wait` before each handle() how long it may wait (a program that stays
  /// awake when a message is due, sg::vision::FrameCadence); keep `wait` short enough (100 ms)
  /// for shutdown to be noticed.
  void spin(const std::function<bool()>& keep_going,
            const std::function<std::chrono::microseconds()>& wait);

  /// True once a `file://` bus has reached the end of its log.
  bool end_of_log() const { return end_of_log_; }

  /// Publishes a process_status_t on PROCESS_STATUS now and then once a second (from handle()
  /// and spin()), for `process` (the program's name), in state `state` (STATE_READY: a program
  /// announces once it serves; STATE_STARTING while it waits for something, set_state() when
  /// that comes). From then on the bus also listens to PROCESS_STATUS and echoes the other
  /// processes' statuses in its own, so each measures its clock's offset to the others
  /// (sg::ClockSync, docs/lab.md). The last status, from spin() when a shutdown was requested or
  /// else from the destructor, is STATE_STOPPING: a watcher tells a process that stopped from one
  /// that died.
  void announce(const std::string& process,
                int8_t state = stereograsp::process_status_t::STATE_READY,
                const std::string& detail = "");

  /// Changes the state PROCESS_STATUS reports, and publishes it at once when it changed.
  void set_state(int8_t state, const std::string& detail = "");

  /// Publishes PROCESS_STATUS if a second has passed since the last one (after announce()).
  /// handle() and spin() call it; a program that polls LCM's file descriptor itself and calls
  /// handle() only when a message is there calls it in its loop.
  void tick();

  /// Counts a message the program decoded but refused (an implausible value, a stale time, an
  /// unauthenticated command), with the one-line reason; logged like a decode error.
  void note_refused(const std::string& channel, const std::string& why);

  uint64_t messages_received() const { return messages_received_; }
  uint64_t decode_errors() const { return decode_errors_; }
  uint64_t handler_errors() const { return handler_errors_; }
  uint64_t refused_inputs() const { return refused_inputs_; }
  uint64_t publish_errors() const { return publish_errors_; }
  /// Messages the guard refused (none without a guard).
  uint64_t unvouched_inputs() const { return unvouched_inputs_; }
  /// Those refusals by (channel, claimed sender, verdict); at most kUnvouchedRows rows, the rest
  /// under channel "(other)".
  struct UnvouchedKey {
    std::string channel;
    std::string sender;
    GuardVerdict verdict = GuardVerdict::kUnsigned;
    auto operator<=>(const UnvouchedKey&) const = default;
  };
  static constexpr std::size_t kUnvouchedRows = 32;
  const std::map<UnvouchedKey, uint64_t>& unvouched() const { return unvouched_; }
  /// When the last publish() handed its bytes to LCM (sg::now_utime(), read just before LCM's
  /// send): the moment a message leaves its publisher. On one host the send then delivers the
  /// datagram to the host's own subscribers before it returns, in the publisher's thread, and a
  /// subscriber woken on its core may run first (issue 19, docs/performance.md).
  int64_t last_handed_utime() const { return last_handed_utime_; }
  /// The newest refusal or failure, one line ("" when none).
  const std::string& last_problem() const { return last_problem_; }
  /// The status PROCESS_STATUS carries at `utime`: counts, state, per-channel counts and rates
  /// (since the previous call), and the clock echoes (process and host as announce()d).
  stereograsp::process_status_t process_status(int64_t utime);

  /// Clock offsets to the other announced processes (empty before announce()).
  const ClockSync* clock_sync() const { return clock_sync_.get(); }

  /// True when LCM's receive socket carries a kernel filter (sg::attach_lcm_channel_filter) that
  /// lets through only the channels subscribed through this bus: on a `udpm://` bus whose
  /// subscriptions all name one channel each (no pattern such as "BLOB_.*", which lifts it).
  /// The datagrams of other channels, which LCM would read and drop, then wake no thread here.
  bool lcm_filtered() const { return lcm_filtered_; }

  /// The underlying LCM object, for what this wrapper does not cover. Subscribe through the bus,
  /// not here: LCM's socket delivers only the channels the bus subscribed (lcm_filtered()).
  lcm::LCM& lcm() { return *lcm_; }

 private:
  class RawHandler;
  struct Direct;
  /// A raw handler that calls `handler` with the message decoded (sg::safe_decode), or counts
  /// and logs why it does not decode as Message.
  template <class Message>
  std::function<void(const RawMessage&)> decoding(
      std::function<void(const Message&, const ReceiveInfo&)> handler) {
    return [this, handler = std::move(handler)](const RawMessage& raw) {
      Message message{};
      if (DecodeResult r = safe_decode(raw.data, raw.info.size, message); !r) {
        report_decode_error(raw.info, r.reason);
        return;
      }
      handler(message, raw.info);
    };
  }
  /// Reads what waits on the bus's own socket; true when a message was dispatched.
  bool drain_direct();
  /// Puts the bytes in buffer_ on the bus, the guard's trailer appended when there is one.
  bool send_buffer(const std::string& channel);
  /// Whether a received message may reach a handler, and how many of its bytes are the LCM
  /// encoding (the guard's verdict; without a guard, all but a well-formed trailer).
  bool admit(const std::string& channel, const uint8_t* data, size_t size, size_t& payload);
  void report_unvouched(const std::string& channel, const GuardResult& result);
  bool handle_lcm(int timeout_ms);
  void report_decode_error(const ReceiveInfo& info, const std::string& why);
  void report_handler_error(const std::string& channel, const std::string& what);
  /// Logs the first ten problems of a kind, then one in a thousand: a wrong publisher must not
  /// flood the log.
  void note_problem(uint64_t count, const std::string& line);

  std::string url_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::vector<std::unique_ptr<RawHandler>> handlers_;
  std::unique_ptr<Direct> direct_;  // with subscribe_direct() on a udpm:// bus
  /// Subscriptions made through LCM. A bus that reads directly and has none never asks LCM for
  /// a message: LCM then starts no receive thread, which would read every datagram on the group
  /// a second time (a second reader woken by each camera frame: p99 3 ms on a 2-vCPU machine,
  /// docs/performance.md).
  int lcm_subscriptions_ = 0;
  /// LCM's receive socket (-1: not found, or not udpm) and the channels its filter lets through;
  /// a pattern among the subscriptions lets everything through.
  int lcm_socket_ = -1;
  std::vector<std::string> lcm_channels_;
  bool lcm_channels_any_ = false;
  bool lcm_filtered_ = false;
  /// This process's UDP sockets on the bus's port (none: not udpm).
  std::vector<int> lcm_sockets() const;
  /// Takes the one socket that is new since `before` as LCM's.
  void find_lcm_socket(const std::vector<int>& before);
  /// Attaches (or lifts) the filter for the subscriptions so far.
  void filter_lcm_socket();
  std::vector<uint8_t> buffer_;
  uint64_t messages_received_ = 0;
  uint64_t decode_errors_ = 0;
  uint64_t handler_errors_ = 0;
  uint64_t refused_inputs_ = 0;
  uint64_t publish_errors_ = 0;
  uint64_t unvouched_inputs_ = 0;
  std::map<UnvouchedKey, uint64_t> unvouched_;
  std::shared_ptr<MessageGuard> guard_;
  /// LCM hands one message to every subscription it matches, one after another within one
  /// handle: the guard judges it once (a second check would call it a replay), and the others
  /// get that verdict: the same handle (dispatch_ counts them), channel, bytes and size. Only
  /// within Bus::handle (in_lcm_handle_): an `lcm().handle()` of a caller's own gets no shared
  /// verdict, so a second subscription may refuse (never believe) what the first accepted.
  uint64_t dispatch_ = 0;
  bool in_lcm_handle_ = false;
  struct Admitted {
    uint64_t dispatch = ~uint64_t{0};
    std::string channel;
    const uint8_t* data = nullptr;
    size_t size = 0;
    bool accepted = false;
    size_t payload = 0;
  } admitted_;
  int64_t last_handed_utime_ = 0;
  std::string last_problem_;
  std::string process_, host_;  // as announce()d; "" = no PROCESS_STATUS
  int8_t state_ = stereograsp::process_status_t::STATE_READY;
  std::string state_detail_;
  int64_t start_utime_ = 0;
  ChannelRates rates_;
  std::unique_ptr<ClockSync> clock_sync_;
  void publish_status();
  std::chrono::steady_clock::time_point next_status_{};
  bool end_of_log_ = false;
};

}  // namespace sg
