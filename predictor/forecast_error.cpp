#include "predictor/forecast_error.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sg::predictor {

ForecastError::ForecastError(int horizon, int max_gap, const ForecastErrorParams& p)
    : horizon_(horizon), params_(p) {
  if (horizon < 1 || max_gap < 0 || p.window < 1)
    throw std::invalid_argument("forecast error: horizon and window must be positive");
  if (!(p.prior_sigma > 0) || !std::isfinite(p.prior_sigma) || !(p.min_sigma > 0) ||
      !std::isfinite(p.min_sigma))
    throw std::invalid_argument("forecast error: prior_sigma and min_sigma must be positive");
  const size_t n = static_cast<size_t>(horizon) + static_cast<size_t>(max_gap);
  mean_square_.resize(n);
  scores_.assign(n, 0);
  for (size_t b = 0; b < n; ++b) {
    const double s = p.prior_sigma * static_cast<double>(b + 1);
    mean_square_[b] = Eigen::Vector3d::Constant(s * s);
  }
  kept_.resize(static_cast<size_t>(horizon));
  for (Kept& k : kept_) k.positions.reserve(static_cast<size_t>(horizon));
}

size_t ForecastError::bucket(int samples) const {
  return static_cast<size_t>(std::clamp(samples, 1, horizons()) - 1);
}

void ForecastError::record(int64_t utime, int occluded, const std::vector<Eigen::Vector3d>& pos,
                           int64_t period_us) {
  if (period_us <= 0 || occluded < 0) return;
  if (count_ > 0 && utime <= kept_[(next_ + kept_.size() - 1) % kept_.size()].utime) return;
  Kept& k = kept_[next_];
  k.utime = utime;
  k.period_us = period_us;
  k.occluded = occluded;
  k.points = static_cast<int>(std::min(pos.size(), static_cast<size_t>(horizon_)));
  k.positions.assign(pos.begin(), pos.begin() + k.points);  // within the reserved capacity
  next_ = (next_ + 1) % kept_.size();
  count_ = std::min(count_ + 1, kept_.size());
}

void ForecastError::score(int64_t utime, const Eigen::Vector3d& sample,
                          const Eigen::Vector3d& sample_sigma) {
  if (!sample.allFinite() || (scored_ && utime <= last_scored_)) return;
  Eigen::Vector3d noise = Eigen::Vector3d::Zero();
  if (sample_sigma.allFinite()) noise = sample_sigma.cwiseAbs2().cwiseMin(1e12);
  scored_ = true;
  last_scored_ = utime;
  for (size_t i = 0; i < count_; ++i) {
    const Kept& k = kept_[(next_ + kept_.size() - 1 - i) % kept_.size()];
    const int64_t ahead = utime - k.utime;
    if (ahead <= 0 || ahead % k.period_us != 0 || ahead / k.period_us > k.points) continue;
    const int h = static_cast<int>(ahead / k.period_us);
    const Eigen::Vector3d e = sample - k.positions[static_cast<size_t>(h - 1)];
    if (!(e.cwiseAbs().maxCoeff() <= 1e6)) continue;  // NaN too
    const size_t b = bucket(h + k.occluded);
    const double lambda = std::max(1.0 / static_cast<double>(scores_[b] + 2), 1.0 / params_.window);
    mean_square_[b] += lambda * (e.cwiseAbs2() - noise - mean_square_[b]);
    ++scores_[b];
  }
}

void ForecastError::reset() {
  next_ = 0;
  count_ = 0;
  scored_ = false;
}

Eigen::Vector3d ForecastError::sigma(int samples) const {
  return mean_square_[bucket(samples)].cwiseMax(0).cwiseSqrt().cwiseMax(params_.min_sigma);
}

int64_t ForecastError::scores(int samples) const { return scores_[bucket(samples)]; }

}  // namespace sg::predictor
