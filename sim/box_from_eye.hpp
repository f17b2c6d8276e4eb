#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <utility>

#include "sim/primitives.hpp"

namespace sg::sim {

/// A box as the rays from one eye meet it. The renderer casts every ray of a frame from the camera
/// centre, so the eye in the box's frame, o = R^T (eye - t), and the box's axes (the rows of R^T)
/// are computed once a frame; a ray along unit d then costs the slab method of Box::intersect on
/// o and R^T d, in scalars (no matrix formed, no temporaries: it runs for every ray, and under
/// AddressSanitizer Eigen's temporaries made the gripper 19 times slower than in Release). It
/// also says which face a ray hits, so a matte box's pixel is a look-up of that face's colour.
///
///     sg::sim::BoxFromEye box(gripper_palm, camera_centre);
///     box.shade_faces(gripper_palm.material, to_light);
///     int face;
///     const double t = box.intersect(direction, &face);   // infinity: missed
///     if (std::isfinite(t) && box.flat) colour = box.face_colour[face];
struct BoxFromEye {
  BoxFromEye(const Box& box, const Eigen::Vector3d& eye) {
    const Eigen::Matrix3d r = box.pose.linear();
    const Eigen::Vector3d t = box.pose.translation();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) axes[3 * i + j] = r(j, i);  // row i of R^T: the box's axis i
      half[i] = box.half_size[i];
      to_centre[i] = t[i] - eye[i];
    }
    for (int i = 0; i < 3; ++i) {
      eye_in_box[i] = -(axes[3 * i] * to_centre[0] + axes[3 * i + 1] * to_centre[1] +
                        axes[3 * i + 2] * to_centre[2]);
    }
    centre_distance2 =
        to_centre[0] * to_centre[0] + to_centre[1] * to_centre[1] + to_centre[2] * to_centre[2];
    bound2 = box.half_size.squaredNorm();
  }

  /// Distance along unit `d` from the eye to the first hit in front of it, or infinity; `face`
  /// gets the face hit: 2 i for the box's -axis i, 2 i + 1 for its +axis i.
  double intersect(const double* d, int* face) const {
    constexpr double kMiss = std::numeric_limits<double>::infinity();
    const double along = to_centre[0] * d[0] + to_centre[1] * d[1] + to_centre[2] * d[2];
    if (centre_distance2 - along * along > bound2) return kMiss;  // outside the bounding sphere
    double near = -kMiss, far = kMiss;
    int near_face = -1, far_face = -1;
    for (int i = 0; i < 3; ++i) {
      const double di = axes[3 * i] * d[0] + axes[3 * i + 1] * d[1] + axes[3 * i + 2] * d[2];
      if (std::abs(di) < 1e-12) {
        if (std::abs(eye_in_box[i]) > half[i]) return kMiss;
        continue;
      }
      double t0 = (-half[i] - eye_in_box[i]) / di;  // where the ray meets the -half plane
      double t1 = (half[i] - eye_in_box[i]) / di;
      int f0 = 2 * i, f1 = 2 * i + 1;
      if (t0 > t1) std::swap(t0, t1), std::swap(f0, f1);
      if (t0 > near) near = t0, near_face = f0;
      if (t1 < far) far = t1, far_face = f1;
      if (near > far) return kMiss;
    }
    if (far <= 0) return kMiss;
    *face = near > 0 ? near_face : far_face;
    return near > 0 ? near : far;
  }

  /// For a matte box (no highlight, so a face's colour does not depend on the view): each face's
  /// colour under `to_light`, so a pixel on it is a look-up.
  void shade_faces(const Material& material, const Eigen::Vector3d& to_light) {
    flat = material.specular <= 0;
    for (int f = 0; flat && f < 6; ++f) {
      const int i = f / 2;
      const double sign = f % 2 == 1 ? 1.0 : -1.0;
      const Eigen::Vector3d normal(sign * axes[3 * i], sign * axes[3 * i + 1],
                                   sign * axes[3 * i + 2]);
      face_colour[f] = shade(material, normal, -normal, to_light);
    }
  }

  bool flat = false;
  Eigen::Vector3d face_colour[6];

  double axes[9];
  double half[3];
  double to_centre[3];
  double eye_in_box[3];
  double centre_distance2;
  double bound2;
};

}  // namespace sg::sim
