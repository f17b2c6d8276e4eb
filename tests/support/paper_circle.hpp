#pragma once

// The paper's ball path as a training file, shared by the tests that start sg-predictor.

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

namespace sg::test {

/// Four minutes of the paper's circle without drift (0.15 m around (0.45, 0, 0.10), 1 rpm) at
/// 4 Hz as t,x,y,z lines: what `sg-predictor train` learns its starting coefficients from.
inline void write_circle(const std::string& path) {
  std::ofstream out(path);
  for (int k = 0; k < 960; ++k) {
    const double t = 0.25 * k, a = 2 * std::numbers::pi * t / 60.0;
    out << t << "," << 0.45 + 0.15 * std::cos(a) << "," << 0.15 * std::sin(a) << ",0.10\n";
  }
}

}  // namespace sg::test
