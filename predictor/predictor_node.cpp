#include "predictor/predictor_node.hpp"

#include "predictor/trajectory_message.hpp"

namespace sg::predictor {

PredictorNode::PredictorNode(const PredictorSettings& settings, Clock& clock)
    : params_(settings.params), clock_(clock), gate_(settings.gate), predictor_(settings.params) {}

PredictorNode::Output PredictorNode::on_position(const stereograsp::point3_t& position) {
  Output out;
  const Measurement m = measurement_of(position);
  if (gate_.check(m, clock_.utime())) {
    out.refused = gate_.last_refusal();
    return out;
  }
  const uint64_t rejected = predictor_.rejected(), resets = predictor_.resets();
  for (const Forecast& f : predictor_.add(m)) {
    out.trajectories.push_back(to_trajectory_t(f, params_));
  }
  published_ += out.trajectories.size();
  if (predictor_.rejected() > rejected) {
    out.refused = "capture time " + std::to_string(m.utime) + " us not after the last";
  }
  if (predictor_.resets() > resets) out.reset = predictor_.last_reset();
  return out;
}

std::string PredictorNode::status_line() const {
  return "OBJECT_POSITION refused: " + gate_.counts_text() + ", not after the last " +
         std::to_string(predictor_.rejected()) + "; predictor resets " +
         std::to_string(predictor_.resets());
}

}  // namespace sg::predictor
