#include "predictor/trajectory_message.hpp"

namespace sg::predictor {

using stereograsp::trajectory_t;

Measurement measurement_of(const stereograsp::point3_t& m) {
  return {m.utime,
          m.visible != 0,
          {m.position[0], m.position[1], m.position[2]},
          {m.position_sigma[0], m.position_sigma[1], m.position_sigma[2]}};
}

trajectory_t to_trajectory_t(const Forecast& f, const PredictorParams& p) {
  trajectory_t t{};
  t.utime = f.utime;
  t.source_utime = f.source_utime;
  t.start_utime = f.utime + f.period_us;
  t.period_us = f.period_us;
  t.num_points = static_cast<int32_t>(f.positions.size());
  for (const auto& q : f.positions) t.position.push_back({q.x(), q.y(), q.z()});
  for (size_t i = 0; i < f.positions.size(); ++i) {
    const Eigen::Vector3d s = i < f.sigma.size() ? f.sigma[i] : Eigen::Vector3d::Zero();
    t.position_sigma.push_back({s.x(), s.y(), s.z()});
  }
  t.occluded_samples = f.occluded_samples;
  t.status = f.status == TrackStatus::kOccluded ? trajectory_t::STATUS_OCCLUDED
             : f.status == TrackStatus::kLost   ? trajectory_t::STATUS_LOST
                                                : trajectory_t::STATUS_TRACKING;
  t.model = p.model == Model::kBurg     ? trajectory_t::MODEL_BURG
            : p.model == Model::kKalman ? trajectory_t::MODEL_KALMAN
                                        : trajectory_t::MODEL_HOLD;
  t.model_order = p.model == Model::kBurg ? p.burg.order : 0;
  return t;
}

}  // namespace sg::predictor
