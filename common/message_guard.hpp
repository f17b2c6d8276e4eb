#pragma once

/// What a bus asks before it sends or believes a message: the interface between sg::Bus and
/// whatever vouches for data (auth/data_auth.hpp, with the lab's credentials). A bus with a
/// guard appends the guard's trailer to everything it publishes, and hands a handler only what
/// the guard accepted, with the trailer taken off; it counts every refusal per channel, claimed
/// sender and verdict (PROCESS_STATUS). A bus without one strips well-formed trailers and
/// believes everything: a process run with --insecure-no-key, or a tool that only looks.
///
///     class MyGuard : public sg::MessageGuard { ... };
///     bus.set_guard(std::make_shared<MyGuard>());   // before subscribing or publishing

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sg {

/// What became of a received message at the guard, in the order they are checked.
enum class GuardVerdict : int {
  kAccepted = 0,    ///< vouched for by a sender allowed on its channel, untouched, new
  kUnsigned = 1,    ///< no trailer at all
  kMalformed = 2,   ///< the trailer's magic, but not a whole trailer
  kNotAllowed = 3,  ///< its sender may not publish on this channel (or is unknown here)
  kNoTag = 4,       ///< an allowed sender, but no tag for this reader
  kBadTag = 5,      ///< a tag for this reader, but not the one these bytes need
  kReplayed = 6,    ///< its counter is not newer than the last accepted of its instance
  kStale = 7,       ///< its counter is outside now - max_age .. now + max_ahead
};
inline constexpr int kGuardVerdicts = 8;

/// "accepted", "unsigned", "malformed", "not allowed", "no tag", "bad tag", "replayed", "stale".
const char* to_string(GuardVerdict verdict);

struct GuardResult {
  GuardVerdict verdict = GuardVerdict::kAccepted;
  std::size_t payload_size = 0;  ///< the LCM encoding's bytes, when accepted
  std::string sender;            ///< who the trailer claims ("" when unsigned or malformed)
  std::string reason;            ///< unless accepted: one line of printable ASCII
  bool accepted() const { return verdict == GuardVerdict::kAccepted; }
};

class MessageGuard {
 public:
  virtual ~MessageGuard() = default;
  /// The name this process vouches as.
  virtual const std::string& identity() const = 0;
  /// Appends this process's trailer for `channel` to `message` (an LCM encoding).
  virtual void vouch(const std::string& channel, std::vector<uint8_t>& message) = 0;
  /// The verdict on `size` bytes received on `channel` at `now_utime` (this process's clock).
  virtual GuardResult check(const std::string& channel, const uint8_t* data, std::size_t size,
                            int64_t now_utime) = 0;
};

}  // namespace sg
