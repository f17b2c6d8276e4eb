// BoxFromEye against the Box primitive it speeds up: the same hits, distances and faces.

#include "sim/box_from_eye.hpp"

#include <gtest/gtest.h>

#include <random>

namespace sg::sim {
namespace {

/// A tilted box off the origin, and eyes around it (one inside).
Box tilted_box() {
  Box box;
  box.pose.linear() = rotation_from_rpy({0.3, -0.7, 1.1});
  box.pose.translation() = Eigen::Vector3d(0.4, -0.1, 0.2);
  box.half_size = {0.02, 0.065, 0.015};
  return box;
}

// For 20,000 random rays from five eyes: a hit exactly when Box::intersect hits, at the same
// distance, on the face whose outward normal Box::normal_at gives at the hit point.
TEST(BoxFromEye, AgreesWithBoxIntersectAndNormal) {
  const Box box = tilted_box();
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss;
  int hits = 0;
  for (const Eigen::Vector3d& eye :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0.5, 0.6), Eigen::Vector3d(0.4, -0.5, 0.2),
        Eigen::Vector3d(0.4, -0.1, 1), Eigen::Vector3d(0.401, -0.1, 0.2)}) {  // the last inside
    const BoxFromEye fast(box, eye);
    for (int k = 0; k < 4000; ++k) {
      // Half the rays aimed near the box, half anywhere.
      Eigen::Vector3d d(gauss(rng), gauss(rng), gauss(rng));
      if (k % 2 == 0) d = box.pose.translation() - eye + 0.05 * d;
      d.normalize();
      const double dd[3] = {d.x(), d.y(), d.z()};
      int face = -1;
      const double t = fast.intersect(dd, &face);
      const std::optional<double> expected = box.intersect({eye, d});
      ASSERT_EQ(std::isfinite(t), expected.has_value())
          << eye.transpose() << " / " << d.transpose();
      if (!expected) continue;
      ++hits;
      EXPECT_NEAR(t, *expected, 1e-12);
      const Eigen::Vector3d normal = box.normal_at(eye + t * d);
      const int i = face / 2;
      const double sign = face % 2 == 1 ? 1.0 : -1.0;
      const Eigen::Vector3d face_normal = sign * box.pose.linear().col(i);
      EXPECT_GT(normal.dot(face_normal), 1 - 1e-9) << "face " << face;
    }
  }
  EXPECT_GT(hits, 5000);  // enough hits to mean something (6,265 with this seed)
}

// A matte box's face colours are shade() of each face's outward normal; a shiny one has none.
TEST(BoxFromEye, MatteFacesAreShadedOnce) {
  Box box = tilted_box();
  box.material.specular = 0;
  const Eigen::Vector3d to_light = Eigen::Vector3d(0.2, 0.3, 1).normalized();
  BoxFromEye fast(box, Eigen::Vector3d::Zero());
  fast.shade_faces(box.material, to_light);
  ASSERT_TRUE(fast.flat);
  for (int f = 0; f < 6; ++f) {
    const Eigen::Vector3d n = (f % 2 == 1 ? 1.0 : -1.0) * box.pose.linear().col(f / 2);
    EXPECT_TRUE(fast.face_colour[f].isApprox(shade(box.material, n, -n, to_light), 1e-12)) << f;
  }
  box.material.specular = 0.5;
  fast.shade_faces(box.material, to_light);
  EXPECT_FALSE(fast.flat);
}

}  // namespace
}  // namespace sg::sim
