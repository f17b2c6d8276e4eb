#pragma once

/// What sg-vision does with one stereo pair (sections 5.1-5.4): track the ball in both cameras
/// (BlobTracker, eq. 7-22), decide whether it is visible in 3D (both cameras found it), place it
/// by linear triangulation refined on the reprojection error (eq. 23-26) with its uncertainty and
/// flags, and fill the BLOB_LEFT, BLOB_RIGHT and OBJECT_POSITION messages. sg-vision, the
/// in-process grasp trials (system/grasp_trial.hpp) and the benchmarks all call this one class,
/// so a change to the visibility rule or the triangulation reaches every figure.
///
///     sg::vision::StereoStep step(tracker_params, {640, 480}, read_calibration("cams.yaml"));
///     const sg::vision::StereoOutput out = step.process(left, right, frame_number, utime);
///     bus.publish("OBJECT_POSITION", *out.position);      // with a calibration
///     bus.publish("BLOB_LEFT", out.blob[0]);
///
/// A frame of another size restarts both trackers at that size (logged). Pure apart from that
/// log line: no clock, no bus; time is the capture time given.

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>

#include "stereograsp/blob_t.hpp"
#include "stereograsp/point3_t.hpp"
#include "vision/blob_tracker.hpp"
#include "vision/calibration_file.hpp"
#include "vision/stereo_match.hpp"

namespace sg::vision {

/// One stereo pair's result.
struct StereoOutput {
  std::array<Observation, 2> observation;         ///< left, right
  std::array<stereograsp::blob_t, 2> blob;        ///< BLOB_LEFT, BLOB_RIGHT
  std::optional<stereograsp::point3_t> position;  ///< OBJECT_POSITION, with a calibration
};

/// Counts over the pairs processed, for sg-vision's summary.
struct StereoCounts {
  uint64_t pairs = 0;
  std::array<uint64_t, 2> found{0, 0};     ///< pairs where each camera found the ball
  std::array<uint64_t, 2> tracking{0, 0};  ///< ... and was in tracking mode
};

class StereoStep {
 public:
  /// A reprojection error above this (pixels) sets point3_t::FLAG_LARGE_RESIDUAL.
  static constexpr double kLargeResidualPx = 3.0;

  /// With a calibration and the scored selection, the ball is the pair of candidates that
  /// agrees with the cameras' geometry (stereo_match.hpp); a camera whose candidate has no
  /// partner keeps it only while it is tracking the ball in its window.
  StereoStep(const BlobTracker::Params& params, cv::Size size,
             std::optional<StereoCalibration> calibration, const StereoMatchParams& match = {});

  /// Tracks both images (BGR), optionally hinted by the pixels where each camera should see the
  /// ball, and returns the blobs and the position, all stamped `utime`.
  StereoOutput process(const cv::Mat& left, const cv::Mat& right, int64_t frame_number,
                       int64_t utime,
                       const std::array<std::optional<cv::Point2d>, 2>& predicted = {});

  /// The pixels of a `frame`-sized image from `camera` (0 left, 1 right) that the next process()
  /// reads (BlobTracker::next_window; all of it when the size differs and tracking restarts):
  /// a caller may decode only these (frame_decoder.hpp).
  cv::Rect next_window(size_t camera, cv::Size frame,
                       const std::optional<cv::Point2d>& predicted = std::nullopt) const;

  const StereoCounts& counts() const { return counts_; }
  const std::optional<StereoCalibration>& calibration() const { return calibration_; }

 private:
  void reset_size(cv::Size size);
  std::array<int, 2> choose(const std::array<Detection, 2>& d) const;
  std::optional<double> expected_radius(size_t camera) const;

  std::array<BlobTracker, 2> trackers_;
  cv::Size size_;
  std::optional<StereoCalibration> calibration_;
  StereoMatchParams match_;
  StereoCounts counts_;
  std::optional<Eigen::Vector3d> last_position_;  ///< the last triangulated ball
  uint64_t last_position_pair_ = 0;               ///< counts_.pairs when it was
};

/// OBJECT_POSITION from both cameras' observations: visible only when both found the ball
/// (seen_by says which did); then the triangulated centre of the ball's images
/// (Observation::centre) (eq. 26, refined), its per-axis sigma, the reprojection error and the
/// geometry flags; otherwise NaN position and sigma.
stereograsp::point3_t position_of(const std::array<Observation, 2>& o,
                                  const StereoCalibration& calibration, int64_t utime);

}  // namespace sg::vision
