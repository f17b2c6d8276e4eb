#pragma once

/// Units of the C550 serial layer. Everywhere else in stereograsp lengths are metres and angles
/// radians (docs/architecture.md); the controller speaks inches and degrees, and these are the
/// only conversions between the two.
///
///     double inches = sg::arm::to_inches(0.45);          // 17.7165...
///     double radians = sg::arm::from_degrees(90.0);      // pi / 2

#include <numbers>

namespace sg::arm {

inline constexpr double kMetresPerInch = 0.0254;  ///< exact, by definition of the inch

constexpr double to_inches(double metres) { return metres / kMetresPerInch; }
constexpr double from_inches(double inches) { return inches * kMetresPerInch; }
constexpr double to_degrees(double radians) { return radians * 180.0 / std::numbers::pi; }
constexpr double from_degrees(double degrees) { return degrees * std::numbers::pi / 180.0; }

}  // namespace sg::arm
