#pragma once

/// sg-predictor without the bus: OBJECT_POSITION in, OBJECT_TRAJECTORY out, through the
/// plausibility gate (position_gate.hpp) and the predictor. The receive time of each position is
/// read from an injected sg::Clock (the system clock in sg-predictor, a simulated one in tests),
/// the one thing the gate needs that the message does not carry.
///
///     PredictorNode node(settings, sg::system_clock());
///     PredictorNode::Output out = node.on_position(position);   // from the subscription
///     if (!out.refused.empty()) bus.note_refused("OBJECT_POSITION", out.refused);
///     for (const auto& t : out.trajectories) bus.publish("OBJECT_TRAJECTORY", t);

#include <string>
#include <vector>

#include "common/clock.hpp"
#include "predictor/position_gate.hpp"
#include "predictor/predictor_settings.hpp"
#include "predictor/trajectory_predictor.hpp"
#include "stereograsp/point3_t.hpp"
#include "stereograsp/trajectory_t.hpp"

namespace sg::predictor {

class PredictorNode {
 public:
  struct Output {
    std::vector<stereograsp::trajectory_t> trajectories;  ///< to publish, oldest first
    std::string refused;  ///< why the gate or the predictor refused the position ("" if taken)
    std::string reset;    ///< why the predictor reset itself ("" if it did not)
  };

  PredictorNode(const PredictorSettings& settings, Clock& clock);

  /// A position received now (clock.utime()).
  Output on_position(const stereograsp::point3_t& position);

  const PositionGate& gate() const { return gate_; }
  const TrajectoryPredictor& predictor() const { return predictor_; }
  uint64_t published() const { return published_; }
  /// The refusals by reason and the resets, one line: "OBJECT_POSITION refused: non-finite 0,
  /// outside the workspace 30, time far from now 0, not after the last 0; predictor resets 1".
  std::string status_line() const;

 private:
  PredictorParams params_;
  Clock& clock_;
  PositionGate gate_;
  TrajectoryPredictor predictor_;
  uint64_t published_ = 0;
};

}  // namespace sg::predictor
