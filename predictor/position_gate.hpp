#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "predictor/trajectory_predictor.hpp"

namespace sg::predictor {

/// Why a measurement was refused before it reached the predictor.
enum class PositionRefusal {
  kNonFinite,         ///< a visible position with a NaN or an infinity
  kOutsideWorkspace,  ///< a visible position outside the workspace widened by the margin
  kTimeFarFromNow,    ///< a capture time farther than max_time_offset from the receiver's clock
};
constexpr int kPositionRefusals = 3;
/// "non-finite", "outside the workspace", "time far from now".
const char* to_string(PositionRefusal reason);

/// What a plausible OBJECT_POSITION is (docs/prediction.md, "Plausibility gates").
struct PositionGateParams {
  /// The arm's workspace (arm.workspace_min/max, arm_driver/kinematics.hpp: the one definition;
  /// sg-predictor reads it with load_arm_geometry). Unbounded by default.
  Eigen::Vector3d box_min = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  Eigen::Vector3d box_max = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  double margin = 0.25;                    ///< m the ball may be outside the box on every side
  int64_t max_time_offset_us = 5'000'000;  ///< |utime - now| allowed; 0: not checked
};

/// The plausibility gate in front of the predictor: a visible position must be three finite
/// numbers inside [box_min - margin, box_max + margin]; any measurement's capture time must be
/// within max_time_offset of the receiver's clock `now` (both us since the Unix epoch). A refused
/// measurement is counted by reason and must not reach the predictor, so it never enters its
/// history (a forged time in the future would otherwise make every later measurement "not after
/// the last").
///
///     PositionGate gate(params);
///     if (auto why = gate.check(m, clock.utime())) log(to_string(*why));
///     else predictor.add(m);
class PositionGate {
 public:
  explicit PositionGate(const PositionGateParams& params) : params_(params) {}

  /// nullopt when `m` may pass; else the reason (counted, and described in last_refusal()).
  std::optional<PositionRefusal> check(const Measurement& m, int64_t now);

  uint64_t refused(PositionRefusal reason) const { return counts_[static_cast<int>(reason)]; }
  uint64_t refused() const;
  /// The newest refusal as one line ("position (1e+300, 0, 0) m outside the workspace ...").
  const std::string& last_refusal() const { return last_; }
  /// "non-finite 3, outside the workspace 0, time far from now 1".
  std::string counts_text() const;
  const PositionGateParams& params() const { return params_; }

 private:
  std::optional<PositionRefusal> refuse(PositionRefusal reason, std::string line);

  PositionGateParams params_;
  std::array<uint64_t, kPositionRefusals> counts_{};
  std::string last_;
};

}  // namespace sg::predictor
