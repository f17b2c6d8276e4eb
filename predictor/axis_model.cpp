#include "predictor/axis_model.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <deque>
#include <numeric>

#include "predictor/burg.hpp"

namespace sg::predictor {
namespace {

/// One Burg axis. push() and replace_newest() estimate its coefficients at once; the three-axis
/// model (BurgTrajectory) updates its three without estimating and estimates them together.
class BurgAxis : public AxisModel {
 public:
  explicit BurgAxis(const BurgParams& p) : p_(p), a_(p.initial_coefficients) {
    centred_.reserve(static_cast<size_t>(p.window));
  }

  void push(double value, bool measured) override {
    add(value, measured);
    if (measured) estimate();
  }

  void replace_newest(const std::vector<double>& values) override {
    replace(values);
    estimate();
  }

  std::vector<double> forecast(int horizon) const override {
    std::vector<double> out;
    if (history_.empty()) return out;
    const double m = mean_;
    std::vector<double> s;  // centred history, then the forecasts appended
    // The last p samples (at least the newest: without coefficients yet, the forecast holds it).
    const size_t keep = std::max<size_t>(a_.size(), 1);
    const size_t start = history_.size() > keep ? history_.size() - keep : 0;
    for (size_t i = start; i < history_.size(); ++i) s.push_back(history_[i] - m);
    for (int h = 0; h < horizon; ++h) {
      const double next =
          a_.empty() ? s.back() : predict_next(a_, s.data(), static_cast<int>(s.size()));
      s.push_back(next);
      out.push_back(next + m);
    }
    return out;
  }

  /// Appends a sample; a measurement also updates the mean (the coefficients: estimate()).
  void add(double value, bool measured) {
    history_.push_back(value);
    if (static_cast<int>(history_.size()) > p_.window) history_.pop_front();
    // The mean and the coefficients are learnt from measurements only: through an occlusion they
    // stay as they were, and the fed-back samples continue the forecast made at its start.
    if (measured) mean_ = window_mean();
  }

  void replace(const std::vector<double>& values) {
    const size_t n = std::min(values.size(), history_.size());
    for (size_t i = 0; i < n; ++i)
      history_[history_.size() - n + i] = values[values.size() - n + i];
  }

  /// The centred window to estimate from, or nullptr while the window is too short (the offline
  /// coefficients, or none, stand until then).
  const std::vector<double>* centred_window() {
    const int needed =
        p_.initial_coefficients.empty() ? p_.order + 3 : std::max(p_.order + 3, p_.online_after);
    if (static_cast<int>(history_.size()) < needed) return nullptr;
    const double m = mean_;
    centred_.assign(history_.begin(), history_.end());
    for (double& v : centred_) v -= m;
    return &centred_;
  }

  void estimate() {
    if (const auto* c = centred_window())
      a_ = burg(c->data(), static_cast<int>(c->size()), p_.order).coefficients;
  }
  void set_coefficients(std::vector<double> a) { a_ = std::move(a); }
  int order() const { return p_.order; }

 private:
  double window_mean() const {
    if (!p_.remove_mean || history_.empty()) return 0.0;
    return std::accumulate(history_.begin(), history_.end(), 0.0) /
           static_cast<double>(history_.size());
  }

  BurgParams p_;
  std::vector<double> a_;
  std::deque<double> history_;
  double mean_ = 0.0;
  std::vector<double> centred_;
};

/// Three Burg axes with one window length, estimated together in one pass (burg3) when all three
/// windows are ready, as they are after the first seconds: bit for bit three separate axes.
class BurgTrajectory : public TrajectoryModel {
 public:
  explicit BurgTrajectory(const std::array<BurgParams, 3>& p)
      : axes_{BurgAxis(p[0]), BurgAxis(p[1]), BurgAxis(p[2])} {}

  void push(const std::array<double, 3>& value, bool measured) override {
    for (size_t i = 0; i < 3; ++i) axes_[i].add(value[i], measured);
    if (measured) estimate();
  }
  void replace_newest(const std::array<std::vector<double>, 3>& values) override {
    for (size_t i = 0; i < 3; ++i) axes_[i].replace(values[i]);
    estimate();
  }
  std::array<std::vector<double>, 3> forecast(int horizon) const override {
    return {axes_[0].forecast(horizon), axes_[1].forecast(horizon), axes_[2].forecast(horizon)};
  }

 private:
  void estimate() {
    std::array<const std::vector<double>*, 3> c{};
    for (size_t i = 0; i < 3; ++i) c[i] = axes_[i].centred_window();
    const bool together = c[0] && c[1] && c[2] && c[0]->size() == c[1]->size() &&
                          c[1]->size() == c[2]->size() && axes_[0].order() == axes_[1].order() &&
                          axes_[1].order() == axes_[2].order();
    if (!together) {
      for (size_t i = 0; i < 3; ++i)
        if (c[i])
          axes_[i].set_coefficients(
              burg(c[i]->data(), static_cast<int>(c[i]->size()), axes_[i].order()).coefficients);
      return;
    }
    std::array<BurgResult, 3> r = burg3({c[0]->data(), c[1]->data(), c[2]->data()},
                                        static_cast<int>(c[0]->size()), axes_[0].order());
    for (size_t i = 0; i < 3; ++i) axes_[i].set_coefficients(std::move(r[i].coefficients));
  }

  std::array<BurgAxis, 3> axes_;
};

/// Any three axis models side by side.
class AxesTrajectory : public TrajectoryModel {
 public:
  explicit AxesTrajectory(std::array<std::unique_ptr<AxisModel>, 3> axes)
      : axes_(std::move(axes)) {}
  void push(const std::array<double, 3>& value, bool measured) override {
    for (size_t i = 0; i < 3; ++i) axes_[i]->push(value[i], measured);
  }
  void replace_newest(const std::array<std::vector<double>, 3>& values) override {
    for (size_t i = 0; i < 3; ++i) axes_[i]->replace_newest(values[i]);
  }
  std::array<std::vector<double>, 3> forecast(int horizon) const override {
    return {axes_[0]->forecast(horizon), axes_[1]->forecast(horizon), axes_[2]->forecast(horizon)};
  }

 private:
  std::array<std::unique_ptr<AxisModel>, 3> axes_;
};

class KalmanAxis : public AxisModel {
 public:
  explicit KalmanAxis(const KalmanParams& p) : p_(p) {
    const double T = p.period;
    F_ << 1, T, 0, 1;
    Q_ << T * T * T / 3, T * T / 2, T * T / 2, T;
    Q_ *= p.q;
  }
  void push(double value, bool measured) override {
    if (!initialised_) {
      x_ << value, 0;
      P_ << p_.r * p_.r, 0, 0, 1.0;
      initialised_ = true;
      return;
    }
    x_ = F_ * x_;
    P_ = F_ * P_ * F_.transpose() + Q_;
    if (!measured) return;  // coasting through an occlusion
    const double innovation = value - x_[0];
    const double S = P_(0, 0) + p_.r * p_.r;
    const Eigen::Vector2d K = P_.col(0) / S;
    x_ += K * innovation;
    P_ = (Eigen::Matrix2d::Identity() - K * Eigen::RowVector2d(1, 0)) * P_;
  }
  void replace_newest(const std::vector<double>&) override {}  // its state already coasted
  std::vector<double> forecast(int horizon) const override {
    std::vector<double> out;
    for (int h = 1; h <= horizon && initialised_; ++h) out.push_back(x_[0] + x_[1] * p_.period * h);
    return out;
  }

 private:
  KalmanParams p_;
  Eigen::Matrix2d F_, Q_, P_;
  Eigen::Vector2d x_ = Eigen::Vector2d::Zero();
  bool initialised_ = false;
};

class HoldAxis : public AxisModel {
 public:
  void push(double value, bool measured) override {
    if (measured || !has_) last_ = value, has_ = true;
  }
  void replace_newest(const std::vector<double>&) override {}
  std::vector<double> forecast(int horizon) const override {
    return has_ ? std::vector<double>(static_cast<size_t>(horizon), last_) : std::vector<double>{};
  }

 private:
  double last_ = 0;
  bool has_ = false;
};

}  // namespace

std::unique_ptr<AxisModel> make_burg_axis(const BurgParams& p) {
  return std::make_unique<BurgAxis>(p);
}
std::unique_ptr<AxisModel> make_kalman_axis(const KalmanParams& p) {
  return std::make_unique<KalmanAxis>(p);
}
std::unique_ptr<AxisModel> make_hold_axis() { return std::make_unique<HoldAxis>(); }

std::unique_ptr<TrajectoryModel> make_burg_trajectory(const std::array<BurgParams, 3>& p) {
  return std::make_unique<BurgTrajectory>(p);
}
std::unique_ptr<TrajectoryModel> make_axes_trajectory(
    std::array<std::unique_ptr<AxisModel>, 3> axes) {
  return std::make_unique<AxesTrajectory>(std::move(axes));
}

}  // namespace sg::predictor
