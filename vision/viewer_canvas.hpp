#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/message_types.hpp"
#include "vision/calibration_file.hpp"

namespace sg::vision {

/// What one view of the paper's user interface shows (section 5, figure 8).
struct ViewerState {
  std::array<cv::Mat, 2> images;                            ///< left, right (BGR)
  std::array<std::optional<stereograsp::blob_t>, 2> blobs;  ///< from BLOB_LEFT, BLOB_RIGHT
  std::optional<stereograsp::point3_t> position;            ///< OBJECT_POSITION
  std::optional<stereograsp::trajectory_t> trajectory;      ///< OBJECT_TRAJECTORY
  std::optional<stereograsp::grasp_status_t> grasp;         ///< GRASP_STATUS
  const StereoCalibration* calibration = nullptr;           ///< to project the trajectory
  double frame_rate = 0;                                    ///< stereo frames per second
  int64_t utime = 0;
};

/// The search window's colour: yellow, as in the paper's figure 8.
inline const cv::Scalar kWindowColour(0, 255, 255);

/// Draws both images side by side with, per camera, a cross on the centroid, the search window
/// as a yellow box, the major and minor axes and their bounding box, and, below, the 3D position,
/// the grasp state and the frame rate; the predicted trajectory is projected into both images when
/// a calibration is given. `canvas` becomes (2 w) x (h + 40).
void draw_view(const ViewerState& state, cv::Mat& canvas);

}  // namespace sg::vision
