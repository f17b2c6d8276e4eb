#include "predictor/trajectory_predictor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sg::predictor {

Model model_from_name(const std::string& name) {
  if (name == "burg") return Model::kBurg;
  if (name == "kalman") return Model::kKalman;
  if (name == "hold") return Model::kHold;
  throw std::invalid_argument("unknown model '" + name + "' (burg, kalman or hold)");
}

const char* model_name(Model m) {
  return m == Model::kBurg ? "burg" : m == Model::kKalman ? "kalman" : "hold";
}

namespace {

/// `p` when its period, horizon and gap are usable (the error model is sized by them).
const PredictorParams& checked(const PredictorParams& p) {
  if (p.period_us <= 0 || p.horizon < 1 || p.max_gap < 0)
    throw std::invalid_argument("predictor: period, horizon and max_gap must be positive");
  return p;
}

}  // namespace

TrajectoryPredictor::TrajectoryPredictor(const PredictorParams& p)
    : params_(checked(p)), error_(p.horizon, p.max_gap, p.error) {
  if (p.model == Model::kBurg && (p.burg.order < 1 || p.burg.window < p.burg.order + 3))
    throw std::invalid_argument("predictor: the window must hold more than order + 3 samples");
  params_.kalman.period = static_cast<double>(p.period_us) * 1e-6;
  reset();
}

void TrajectoryPredictor::reset() {
  if (params_.model == Model::kBurg) {
    std::array<BurgParams, 3> b{params_.burg, params_.burg, params_.burg};
    for (size_t i = 0; i < 3; ++i)
      if (!params_.initial_coefficients[i].empty())
        b[i].initial_coefficients = params_.initial_coefficients[i];
    model_ = make_burg_trajectory(b);
  } else {
    std::array<std::unique_ptr<AxisModel>, 3> axes;
    for (auto& a : axes)
      a = params_.model == Model::kKalman ? make_kalman_axis(params_.kalman) : make_hold_axis();
    model_ = make_axes_trajectory(std::move(axes));
  }
  newest_one_step_.reset();
  started_ = false;
  have_seen_ = false;
  occluded_ = 0;
  last_gap_ = since_gap_ = 0;
  gating_since_.reset();
  error_.reset();
}

Eigen::Vector3d TrajectoryPredictor::one_step() const {
  if (newest_one_step_) return *newest_one_step_;
  const std::array<std::vector<double>, 3> next = model_->forecast(1);
  return {next[0].front(), next[1].front(), next[2].front()};
}

Forecast TrajectoryPredictor::emit_sample(int64_t grid, const Eigen::Vector3d& value, bool measured,
                                          int64_t source) {
  if (measured && occluded_ > 0) {  // back from an occlusion: the gap becomes the straight line
    std::array<std::vector<double>, 3> line;
    for (int i = 0; i < 3; ++i) {
      for (int k = 1; k <= occluded_; ++k) {
        const double s = static_cast<double>(k) / (occluded_ + 1);
        line[static_cast<size_t>(i)].push_back(last_real_value_[i] +
                                               s * (value[i] - last_real_value_[i]));
      }
    }
    model_->replace_newest(line);
    last_gap_ = occluded_;
    since_gap_ = 0;
    occluded_ = 0;
  }
  model_->push({value[0], value[1], value[2]}, measured);
  if (measured) error_.score(grid, value, measured_sigma_);
  if (measured) {
    last_real_grid_ = grid;
    last_real_value_ = value;
    status_ = TrackStatus::kTracking;
  } else {
    ++occluded_;
    status_ = TrackStatus::kOccluded;
  }
  Forecast f;
  f.utime = grid;
  f.source_utime = source;
  f.period_us = params_.period_us;
  f.occluded_samples = occluded_;
  f.status = status_;
  f.sample = value;
  last_sample_ = value;
  const std::array<std::vector<double>, 3> axis = model_->forecast(params_.horizon);
  // The model stays as it is until the next grid sample: its one-step forecast is this one's first
  // point (forecast(1) computes it in the same order), for the gate and a fed-back sample.
  newest_one_step_.reset();
  if (!axis[0].empty() && !axis[1].empty() && !axis[2].empty())
    newest_one_step_ = Eigen::Vector3d(axis[0].front(), axis[1].front(), axis[2].front());
  // The samples the published sigma counts past a measurement (PredictorParams::after_gap).
  const int unseen = occluded_ > 0 ? occluded_ : since_gap_ < params_.after_gap ? last_gap_ : 0;
  if (measured && since_gap_ < params_.after_gap) ++since_gap_;
  f.positions.reserve(static_cast<size_t>(params_.horizon));
  f.sigma.reserve(static_cast<size_t>(params_.horizon));
  for (int h = 0; h < params_.horizon; ++h) {
    f.positions.emplace_back(axis[0][static_cast<size_t>(h)], axis[1][static_cast<size_t>(h)],
                             axis[2][static_cast<size_t>(h)]);
    f.sigma.push_back(error_.sigma(h + 1 + unseen));
  }
  error_.record(grid, occluded_, f.positions, params_.period_us);
  return f;
}

bool TrajectoryPredictor::outside_gate(const Measurement& m) {
  // While tracking, or while a run of gated measurements has made the samples fed back.
  const bool gating =
      status_ == TrackStatus::kTracking || (gating_since_ && status_ == TrackStatus::kOccluded);
  if (!(params_.gate > 0) || !m.visible || !gating) return false;
  // Where the forecast puts the ball at m.utime: between the newest grid sample and the next.
  const int64_t newest = next_grid_ - params_.period_us;
  const double s = std::clamp(
      static_cast<double>(m.utime - newest) / static_cast<double>(params_.period_us), 0.0, 2.0);
  const Eigen::Vector3d expected = last_sample_ + s * (one_step() - last_sample_);
  if ((m.position - expected).norm() <= params_.gate) {
    gating_since_.reset();
    return false;
  }
  if (!gating_since_) gating_since_ = m.utime;
  if (m.utime - *gating_since_ > params_.gate_patience_us) {  // it really is there
    gating_since_.reset();
    return false;
  }
  ++gated_;
  return true;
}

std::string TrajectoryPredictor::insane(const Forecast& f) const {
  const double limit = params_.reset_distance;
  if (!f.sample.allFinite() || !(f.sample.norm() <= limit)) {
    return "sample (" + std::to_string(f.sample.x()) + ", " + std::to_string(f.sample.y()) + ", " +
           std::to_string(f.sample.z()) + ") m is not within " + std::to_string(limit) +
           " m of the base";
  }
  for (size_t h = 0; h < f.positions.size(); ++h) {
    const double d = (f.positions[h] - f.sample).norm();
    if (!(d <= limit)) {
      return "forecast point " + std::to_string(h + 1) + " is " + std::to_string(d) +
             " m from the newest sample (at most " + std::to_string(limit) + " m)";
    }
  }
  return "";
}

Forecast TrajectoryPredictor::recover(int64_t grid_utime, int64_t source, std::string why) {
  Forecast lost;
  lost.utime = grid_utime;
  lost.source_utime = source;
  lost.period_us = params_.period_us;
  lost.status = status_ = TrackStatus::kLost;
  reset();
  ++resets_;
  last_reset_ = std::move(why);
  return lost;
}

std::vector<Forecast> TrajectoryPredictor::add(const Measurement& in) {
  std::vector<Forecast> out;
  if (in.visible && !in.position.allFinite()) {
    ++rejected_;
    return out;
  }
  if (started_ && in.utime <= last_utime_) {
    if (++backward_run_ < kMaxBackwardRun) {
      ++rejected_;
      return out;
    }
    out.push_back(recover(in.utime, in.utime,
                          std::to_string(kMaxBackwardRun) +
                              " measurements in a row not after the last (the clock went back)"));
  }
  backward_run_ = 0;
  Measurement m = in;
  // A sigma that is not a sigma (NaN, negative, over a metre) is taken as unknown.
  measured_sigma_ = (m.sigma.array() >= 0).all() && (m.sigma.array() <= 1).all()
                        ? m.sigma
                        : Eigen::Vector3d::Zero();
  if (outside_gate(m)) m.visible = false;
  last_utime_ = m.utime;
  if (!started_) {
    if (!m.visible) return out;  // nothing to predict from yet
    started_ = true;
    next_grid_ = m.utime;
  }
  // Grid samples up to this measurement's time: interpolated between two visible measurements
  // close in time, fed back otherwise.
  while (next_grid_ <= m.utime) {
    const bool interpolate =
        m.visible && have_seen_ && m.utime - seen_utime_ <= 2 * params_.period_us;
    std::optional<Forecast> f;
    if (next_grid_ == m.utime && m.visible) {
      f = emit_sample(next_grid_, m.position, true, m.utime);
    } else if (interpolate && next_grid_ >= seen_utime_) {
      const double s = static_cast<double>(next_grid_ - seen_utime_) /
                       static_cast<double>(m.utime - seen_utime_);
      f = emit_sample(next_grid_, seen_position_ + s * (m.position - seen_position_), true,
                      m.utime);
    }
    if (!f) {
      if (occluded_ >= params_.max_gap) {  // lost: start again from the next sighting
        Forecast lost;
        lost.utime = next_grid_;
        lost.source_utime = m.utime;
        lost.period_us = params_.period_us;
        lost.occluded_samples = occluded_;
        lost.status = status_ = TrackStatus::kLost;
        out.push_back(lost);
        reset();
        if (m.visible) {
          started_ = true;
          next_grid_ = m.utime;
          continue;
        }
        return out;
      }
      f = emit_sample(next_grid_, one_step(), false, m.utime);
    }
    if (std::string why = insane(*f); !why.empty()) {  // start again from the next sighting
      out.push_back(recover(f->utime, m.utime, std::move(why)));
      return out;
    }
    out.push_back(std::move(*f));
    next_grid_ += params_.period_us;
  }
  if (m.visible) {
    have_seen_ = true;
    seen_utime_ = m.utime;
    seen_position_ = m.position;
  }
  return out;
}

}  // namespace sg::predictor
