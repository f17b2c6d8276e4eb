#include "common/message_guard.hpp"

namespace sg {

const char* to_string(GuardVerdict verdict) {
  switch (verdict) {
    case GuardVerdict::kAccepted:
      return "accepted";
    case GuardVerdict::kUnsigned:
      return "unsigned";
    case GuardVerdict::kMalformed:
      return "malformed";
    case GuardVerdict::kNotAllowed:
      return "not allowed";
    case GuardVerdict::kNoTag:
      return "no tag";
    case GuardVerdict::kBadTag:
      return "bad tag";
    case GuardVerdict::kReplayed:
      return "replayed";
    case GuardVerdict::kStale:
      return "stale";
  }
  return "?";
}

}  // namespace sg
