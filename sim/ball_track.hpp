#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <optional>

namespace sg::sim {

/// The ball's true centre between GROUND_TRUTH messages, for sg-c550-sim's CLOSE: the cameras
/// publish the truth once a frame (every 0.25 s at the paper's 4 Hz), and a ball moving 31 mm/s
/// (2 rpm on a 0.15 m circle) is up to 8 mm from its last sample when the hand closes. at()
/// extrapolates the last two samples linearly to the time asked (at most `max_extrapolation`
/// past the newest; 0.3 mm off a 0.10 m circle at 2 rpm over a 0.25 s frame), and holds the
/// newest when there is only one, or when the two are more than `max_gap` apart or out of order.
///
///     BallTrack track;
///     track.add(frame_utime, centre);      // each GROUND_TRUTH
///     controller.close(t, track.at(now));  // where the ball is now
class BallTrack {
 public:
  static constexpr int64_t kMaxGap = 1'000'000;          ///< us between the two samples
  static constexpr int64_t kMaxExtrapolation = 500'000;  ///< us past the newest sample

  /// A sample captured at `utime`; a non-finite centre (the ball unknown) clears the track.
  void add(int64_t utime, const Eigen::Vector3d& centre) {
    if (!centre.allFinite()) {
      newest_.reset();
      previous_.reset();
      return;
    }
    previous_ = newest_;
    newest_ = Sample{utime, centre};
  }

  /// The centre at `utime`; nullopt before any sample. Any GROUND_TRUTH can arrive (times
  /// near the int64 limits, centres near 1e308): the times are subtracted in double, never
  /// overflowing, the extrapolation stays within max_extrapolation either side of the newest
  /// sample, and a result that is not finite is the newest sample.
  std::optional<Eigen::Vector3d> at(int64_t utime) const {
    if (!newest_) return std::nullopt;
    if (!previous_) return newest_->centre;
    const double span = static_cast<double>(newest_->utime) - static_cast<double>(previous_->utime);
    if (!(span > 0) || span > kMaxGap) return newest_->centre;
    const double limit = static_cast<double>(kMaxExtrapolation);
    const double ahead =
        std::clamp(static_cast<double>(utime) - static_cast<double>(newest_->utime), -limit, limit);
    const Eigen::Vector3d p =
        newest_->centre + (newest_->centre - previous_->centre) * (ahead / span);
    return p.allFinite() ? p : newest_->centre;
  }

 private:
  struct Sample {
    int64_t utime;
    Eigen::Vector3d centre;
  };
  std::optional<Sample> newest_, previous_;
};

}  // namespace sg::sim
