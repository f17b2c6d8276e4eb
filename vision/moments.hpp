#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>

namespace sg::vision {

/// Raw moments M_pq (eq. 9) of a binary region, p + q <= 2, summed exactly in integers over
/// pixel-centre coordinates (x right, y down, origin at the centre of the top-left pixel).
struct RawMoments {
  int64_t m00 = 0, m10 = 0, m01 = 0, m20 = 0, m02 = 0, m11 = 0;

  void add(int64_t x, int64_t y) {
    m00 += 1, m10 += x, m01 += y, m20 += x * x, m02 += y * y, m11 += x * y;
  }
};

/// What the paper's tracking stage (section 5.3) derives from a region's moments.
struct Blob {
  cv::Point2d centroid;                 ///< (x_c, y_c), eq. 11
  double area = 0;                      ///< M00 = mu00, eq. 12
  double mu20 = 0, mu02 = 0, mu11 = 0;  ///< central moments, eq. 13-15
  double major_axis = 0;   ///< l: full length of the major axis, eq. 16 (see blob_from_moments)
  double minor_axis = 0;   ///< w: full length of the minor axis, eq. 17
  double orientation = 0;  ///< theta, eq. 18, radians from +x toward +y
  std::array<cv::Point2d, 2> major_axis_ends;  ///< l1, l2, eq. 19-20
  std::array<cv::Point2d, 2> minor_axis_ends;  ///< w1, w2, eq. 21-22
  cv::Rect2d bounding_box;                     ///< the box the four axis end points define
};

/// Centroid, central moments, axes, orientation, axis end points and bounding box (eq. 11-22).
///
/// The axes are the full lengths of the ellipse with the region's second moments:
///   l, w = sqrt( 8 [mu20 + mu02 +- sqrt((mu20 - mu02)^2 + 4 mu11^2)] / mu00 ),
/// so that for a filled ellipse of semi-axes a >= b, l = 2a and w = 2b, and the end points of
/// eq. 19-22 (at +-l/2, +-w/2 from the centroid) lie on its boundary. The paper's eq. 16-17
/// divide by mu00/2 instead of mu00/8, which gives the semi-axes and would put those end points
/// halfway to the boundary.
Blob blob_from_moments(const RawMoments& m);

}  // namespace sg::vision
