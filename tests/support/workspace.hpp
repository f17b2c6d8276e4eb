#pragma once

#include <Eigen/Core>
#include <random>
#include <vector>

namespace sg::test {

/// `n` points spread uniformly through the robot's workspace (robot frame, m):
/// X 0.2-0.7, Y -0.3-0.3, Z 0-0.3; the same seed gives the same points.
inline std::vector<Eigen::Vector3d> workspace_points(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(0.2, 0.7), y(-0.3, 0.3), z(0.0, 0.3);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.emplace_back(x(rng), y(rng), z(rng));
  return points;
}

}  // namespace sg::test
