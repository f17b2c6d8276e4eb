#pragma once

#include <cstdint>
#include <cstdlib>
#include <optional>
#include <utility>

namespace sg::vision {

/// Matches left and right frames that arrive separately (CAMERA_LEFT, CAMERA_RIGHT) by capture
/// time: a pair is two frames whose utimes differ by at most `tolerance_us`. A frame that cannot
/// be matched any more (its partner's side has moved past it) is counted as unmatched and dropped.
///
///     StereoPairer<Frame> pairer(5000);
///     if (auto pair = pairer.add(0, left_utime, std::move(left))) process(pair->first,
///     pair->second);
template <class Frame>
class StereoPairer {
 public:
  explicit StereoPairer(int64_t tolerance_us) : tolerance_us_(tolerance_us) {}

  /// Adds a frame from `side` (0 left, 1 right); returns a complete pair when this frame makes one.
  std::optional<std::pair<Frame, Frame>> add(int side, int64_t utime, Frame frame) {
    Slot& other = slots_[1 - side];
    if (other.frame && std::llabs(other.utime - utime) <= tolerance_us_) {
      Frame partner = std::move(*other.frame);
      other.frame.reset();
      if (side == 0) return std::pair<Frame, Frame>{std::move(frame), std::move(partner)};
      return std::pair<Frame, Frame>{std::move(partner), std::move(frame)};
    }
    if (other.frame && other.utime < utime) {  // the other side's frame will never be matched
      other.frame.reset();
      ++unmatched_;
    }
    Slot& mine = slots_[side];
    if (mine.frame) ++unmatched_;  // replaced before its partner came
    mine.frame = std::move(frame);
    mine.utime = utime;
    return std::nullopt;
  }

  uint64_t unmatched() const { return unmatched_; }

 private:
  struct Slot {
    std::optional<Frame> frame;
    int64_t utime = 0;
  };
  int64_t tolerance_us_;
  Slot slots_[2];
  uint64_t unmatched_ = 0;
};

}  // namespace sg::vision
