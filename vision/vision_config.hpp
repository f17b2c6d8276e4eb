#pragma once

#include <string>

#include "common/config.hpp"
#include "vision/blob_tracker.hpp"
#include "vision/stereo_match.hpp"

namespace sg::vision {

/// What sg-vision is configured with: the `vision` section (docs/vision.md).
struct VisionSettings {
  BlobTracker::Params tracker;
  StereoMatchParams match;  ///< the ball's radius and the stereo pairing
  std::string calibration;  ///< a stereo calibration file; with it OBJECT_POSITION is published
  /// JPEGs from the bus: "region" decodes only the search windows while tracking
  /// (frame_decoder.hpp), "full" every frame whole (the baseline).
  std::string decode = "region";
  /// CAMERA_LEFT and CAMERA_RIGHT on a udpm:// bus: "direct" reads them on sg-vision's own
  /// socket on the bus's group, in the thread that tracks (Bus::subscribe_direct, issue 19);
  /// "lcm" through LCM's subscription and receive thread, as every other channel.
  std::string camera_read = "direct";
  /// SCHED_FIFO priority for sg-vision and its LCM thread, with its memory locked
  /// (common/realtime.hpp); 0: the ordinary scheduler.
  int realtime_priority = 0;
  /// How long before and after a stereo pair is due (from the cadence of the last ones)
  /// sg-vision's decode workers poll for its first image without sleeping, off the reading
  /// thread's core (vision/frame_cadence.hpp, vision/decode_worker.hpp): a worker woken from
  /// sleep on the lab's virtual machine lands on the reader's core and preempts it, or comes
  /// 0.1-1 ms late. Costs the polling's CPU time, about the intervals' spread plus 2x this per
  /// pair (docs/performance.md, issue 19); 0: the workers sleep until a frame arrives. Not used
  /// at SCHED_FIFO (realtime_priority): a real-time thread that polls keeps the kernel's own
  /// threads off its core.
  double busy_wait_ms = 1.0;
};

/// Reads the `vision` section: every key range-checked, any other key of the section refused
/// with the nearest known one. Absent keys keep the structs' defaults.
VisionSettings read_vision_settings(const Config& config);

/// The tracker's part of read_vision_settings().
inline BlobTracker::Params load_tracker_params(const Config& config) {
  return read_vision_settings(config).tracker;
}

}  // namespace sg::vision
