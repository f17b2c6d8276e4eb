#include "predictor/forecast_error.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sg::predictor {

ForecastError::ForecastError(int horizon, int max_gap, const ForecastErrorParams& p)
    : horizon_(horizon), params_(p) {
  if (horizon < 1 || max_gap < 0 || p.window < 1 || p.window > kMaxWindow)
    throw std::invalid_argument(
        "forecast error: horizon and window must be positive (window at most " +
        std::to_string(kMaxWindow) + ")");
  if (!(p.prior_sigma > 0) || !std::isfinite(p.prior_sigma) || !(p.min_sigma > 0) ||
      !std::isfinite(p.min_sigma))
    throw std::invalid_argument("forecast error: prior_sigma and min_sigma must be positive");
  if (p.surprise_window < 0 || p.surprise_window > 64 || !(p.surprise_threshold > 0) ||
      !std::isfinite(p.surprise_threshold) || p.fresh_scores < 0 || p.fresh_scores > kMaxWindow)
    throw std::invalid_argument(
        "forecast error: surprise_window must be 0 to 64, surprise_threshold positive and "
        "fresh_scores 0 to 10000");
  const size_t n = static_cast<size_t>(horizon) + static_cast<size_t>(max_gap);
  const size_t w = static_cast<size_t>(p.window);
  window_.assign(n * w, Eigen::Vector3d::Zero());
  noise_.assign(n * w, Eigen::Vector3d::Zero());
  sum_.resize(n);
  noise_sum_.assign(n, Eigen::Vector3d::Zero());
  filled_.assign(n, 1);
  head_.assign(n, 1 % p.window);
  scores_.assign(n, 0);
  surprise_ring_.assign(n * static_cast<size_t>(p.surprise_window), Surprise{});
  surprise_sum_.assign(n, Surprise{});
  surprise_filled_.assign(n, 0);
  turn_.assign(n, Eigen::Vector3d::Zero());
  fresh_.assign(n, p.fresh_scores);  // the prior is the estimate itself until scores come
  for (size_t b = 0; b < n; ++b) {   // the prior is each window's first entry
    const double s = p.prior_sigma * static_cast<double>(b + 1);
    window_[b * w] = sum_[b] = Eigen::Vector3d::Constant(s * s);
  }
  estimate_.resize(n);
  widen_.resize(n);
  for (size_t b = 0; b < n; ++b) refresh(b);
  kept_.resize(static_cast<size_t>(horizon));
  for (Kept& k : kept_) k.positions.reserve(static_cast<size_t>(horizon));
}

double ForecastError::predictive_factor(double m) {
  if (m < 2) return 2.0;  // the prior alone, or one score: no spread known
  // Student's t quantile at 0.97725 (the normal's 2 sigma) for nu = m - 1 degrees of freedom,
  // by the Cornish-Fisher expansion: the interval holds within 0.0005 of the normal's 0.97725
  // from m = 8 on (0.9748 at m = 4; the prior and a few scores only at a start).
  const double z = 2.0, nu = m - 1;
  const double t = z + (z * z * z + z) / (4 * nu) +
                   (5 * std::pow(z, 5) + 16 * z * z * z + 3 * z) / (96 * nu * nu);
  return std::min(2.0, t / z * std::sqrt(1 + 1 / m));
}

size_t ForecastError::bucket(int samples) const {
  return static_cast<size_t>(std::clamp(samples, 1, horizons()) - 1);
}

void ForecastError::add(size_t b, const Eigen::Vector3d& value, const Eigen::Vector3d& noise) {
  const size_t w = static_cast<size_t>(params_.window);
  Eigen::Vector3d* ring = &window_[b * w];
  Eigen::Vector3d* noise_ring = &noise_[b * w];
  const size_t head = static_cast<size_t>(head_[b]);
  if (filled_[b] == params_.window) {
    sum_[b] -= ring[head];
    noise_sum_[b] -= noise_ring[head];
  }
  ring[head] = value;
  noise_ring[head] = noise;
  sum_[b] += value;
  noise_sum_[b] += noise;
  filled_[b] = std::min(filled_[b] + 1, params_.window);
  head_[b] = static_cast<int>((head + 1) % w);
  if (head_[b] == 0) {  // once a round, the sum afresh: no rounding drift over a long session
    sum_[b].setZero();
    noise_sum_[b].setZero();
    for (size_t i = 0; i < static_cast<size_t>(filled_[b]); ++i) {
      sum_[b] += ring[i];
      noise_sum_[b] += noise_ring[i];
    }
  }
  refresh(b);
}

void ForecastError::refresh(size_t b) {
  const Eigen::Vector3d square = (sum_[b] - noise_sum_[b]) / static_cast<double>(filled_[b]);
  estimate_[b] = square.cwiseMax(0).cwiseSqrt().cwiseMax(params_.min_sigma);
  widen_[b] = params_.predictive ? predictive_factor(filled_[b]) : 1.0;
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
    const Eigen::Vector3d expected = estimate_[b].cwiseAbs2() + noise;
    add_surprise(b, {(e.cwiseAbs2().array() / expected.array()).mean(), e.cwiseAbs2() - expected});
    add(b, e.cwiseAbs2(), noise);
    ++scores_[b];
    fresh_[b] = std::min(fresh_[b] + 1, params_.fresh_scores);
  }
  update_turn();
}

void ForecastError::add_surprise(size_t b, Surprise s) {
  const int w = params_.surprise_window;
  if (w == 0 || !std::isfinite(s.z2) || !s.excess.allFinite()) return;
  s.z2 = std::min(s.z2, 1e12);
  s.excess = s.excess.cwiseMin(1e12);
  // The ring's slot: scores_ counts every score, so it cycles through the window.
  Surprise& slot = surprise_ring_[b * static_cast<size_t>(w) + static_cast<size_t>(scores_[b] % w)];
  Surprise& sum = surprise_sum_[b];
  if (surprise_filled_[b] == w) sum.z2 -= slot.z2, sum.excess -= slot.excess;
  slot = s;
  sum.z2 += s.z2, sum.excess += s.excess;
  surprise_filled_[b] = std::min(surprise_filled_[b] + 1, w);
  if (scores_[b] % w == w - 1) {  // once a round, the sum afresh (no rounding drift)
    sum = Surprise{};
    const Surprise* ring = &surprise_ring_[b * static_cast<size_t>(w)];
    for (int i = 0; i < surprise_filled_[b]; ++i)
      sum.z2 += ring[i].z2, sum.excess += ring[i].excess;
  }
}

void ForecastError::update_turn() {
  // T_b = b max over surprised b' <= b of eps_b' / b': a prefix maximum, O(buckets).
  Eigen::Vector3d per_sample = Eigen::Vector3d::Zero();
  for (size_t b = 0; b < turn_.size(); ++b) {
    const int m = surprise_filled_[b];
    const double horizon = static_cast<double>(b + 1);
    if (m > 0 && surprise_sum_[b].z2 / m > params_.surprise_threshold) {
      const Eigen::Vector3d eps = (surprise_sum_[b].excess / m).cwiseMax(0).cwiseSqrt();
      per_sample = per_sample.cwiseMax(eps / horizon);
    }
    turn_[b] = horizon * per_sample;
  }
}

void ForecastError::reset() {
  next_ = 0;
  count_ = 0;
  scored_ = false;
  std::fill(fresh_.begin(), fresh_.end(), 0);
}

Eigen::Vector3d ForecastError::sigma(int samples) const {
  const size_t b = bucket(samples);
  Eigen::Vector3d s = widen_[b] * estimate_[b];
  if (fresh_[b] < params_.fresh_scores)  // a new model: no surer than the prior until scored
    s = s.cwiseMax(params_.prior_sigma * static_cast<double>(b + 1));
  return (s.cwiseAbs2() + turn_[b].cwiseAbs2()).cwiseSqrt();
}

Eigen::Vector3d ForecastError::turn(int samples) const { return turn_[bucket(samples)]; }

int64_t ForecastError::scores(int samples) const { return scores_[bucket(samples)]; }

}  // namespace sg::predictor
