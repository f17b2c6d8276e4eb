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
    std::vector<double> s = forecast_start(horizon);  // centred, then the forecasts appended
    out.reserve(static_cast<size_t>(horizon));
    for (int h = 0; h < horizon; ++h) {
      const double next =
          a_.empty() ? s.back() : predict_next(a_, s.data(), static_cast<int>(s.size()));
      s.push_back(next);
      out.push_back(next + mean_);
    }
    return out;
  }

  /// The centred samples a forecast of `horizon` starts from: the last p (at least the newest:
  /// without coefficients yet, the forecast holds it), with room for the forecast.
  std::vector<double> forecast_start(int horizon) const {
    std::vector<double> s;
    const size_t keep = std::max<size_t>(a_.size(), 1);
    const size_t start = history_.size() > keep ? history_.size() - keep : 0;
    s.reserve(history_.size() - start + static_cast<size_t>(std::max(horizon, 0)));
    for (size_t i = start; i < history_.size(); ++i) s.push_back(history_[i] - mean_);
    return s;
  }

  /// Appends a sample; a measurement also updates the mean (the coefficients: estimate()).
  void add(double value, bool measured) {
    append(value);
    // The mean and the coefficients are learnt from measurements only: through an occlusion they
    // stay as they were, and the fed-back samples continue the forecast made at its start.
    if (measured) mean_ = window_mean();
  }

  /// add() without the mean: BurgTrajectory sums its three windows in one pass.
  void append(double value) {
    history_.push_back(value);
    if (static_cast<int>(history_.size()) > p_.window) history_.pop_front();
  }

  void replace(const std::vector<double>& values) {
    const size_t n = std::min(values.size(), history_.size());
    for (size_t i = 0; i < n; ++i)
      history_[history_.size() - n + i] = values[values.size() - n + i];
  }

  /// Whether the window is long enough to estimate from (until then the offline coefficients,
  /// or none, stand).
  bool estimable() const {
    const int needed =
        p_.initial_coefficients.empty() ? p_.order + 3 : std::max(p_.order + 3, p_.online_after);
    return static_cast<int>(history_.size()) >= needed;
  }

  /// The centred window to estimate from, or nullptr while it is not estimable().
  const std::vector<double>* centred_window() {
    if (!estimable()) return nullptr;
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
  const std::vector<double>& coefficients() const { return a_; }
  double mean() const { return mean_; }
  size_t size() const { return history_.size(); }
  bool removes_mean() const { return p_.remove_mean; }
  const std::deque<double>& history() const { return history_; }
  void set_mean(double m) { mean_ = m; }

  /// The window's mean (0 when the mean is not removed): its samples summed in order from 0.
  double window_mean() const {
    if (!p_.remove_mean || history_.empty()) return 0.0;
    return std::accumulate(history_.begin(), history_.end(), 0.0) /
           static_cast<double>(history_.size());
  }

 private:
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
    for (size_t i = 0; i < 3; ++i) axes_[i].append(value[i]);
    if (measured) {
      update_means();
      estimate();
    }
  }
  void replace_newest(const std::array<std::vector<double>, 3>& values) override {
    for (size_t i = 0; i < 3; ++i) axes_[i].replace(values[i]);
    estimate();
  }

  /// The three axes' forecasts (eq. 27) in one loop when their orders agree, each axis's sum in
  /// BurgAxis::forecast's order: three independent chains of additions where one axis has one.
  std::array<std::vector<double>, 3> forecast(int horizon) const override {
    const size_t p = axes_[0].coefficients().size(), n = axes_[0].size();
    for (const BurgAxis& a : axes_)
      if (p == 0 || n == 0 || a.coefficients().size() != p || a.size() != n)
        return {axes_[0].forecast(horizon), axes_[1].forecast(horizon), axes_[2].forecast(horizon)};
    std::array<std::vector<double>, 3> s, out;
    for (size_t i = 0; i < 3; ++i) {
      s[i] = axes_[i].forecast_start(horizon);
      out[i].reserve(static_cast<size_t>(horizon));
    }
    const double *a0 = axes_[0].coefficients().data(), *a1 = axes_[1].coefficients().data(),
                 *a2 = axes_[2].coefficients().data();
    for (int h = 0; h < horizon; ++h) {
      const size_t size = s[0].size();
      double n0 = 0, n1 = 0, n2 = 0;  // predict_next's sums
      for (size_t k = 1; k <= p && k <= size; ++k) {
        n0 -= a0[k - 1] * s[0][size - k];
        n1 -= a1[k - 1] * s[1][size - k];
        n2 -= a2[k - 1] * s[2][size - k];
      }
      s[0].push_back(n0), s[1].push_back(n1), s[2].push_back(n2);
      out[0].push_back(n0 + axes_[0].mean());
      out[1].push_back(n1 + axes_[1].mean());
      out[2].push_back(n2 + axes_[2].mean());
    }
    return out;
  }

 private:
  /// Each axis's window mean, as BurgAxis::add computes it (summed in order from 0), the three
  /// sums in one pass.
  void update_means() {
    const size_t n = axes_[0].size();
    bool together = axes_[1].size() == n && axes_[2].size() == n;
    for (const BurgAxis& a : axes_) together = together && a.removes_mean();
    if (!together || n == 0) {
      for (BurgAxis& a : axes_) a.set_mean(a.window_mean());
      return;
    }
    double s0 = 0, s1 = 0, s2 = 0;
    auto i0 = axes_[0].history().begin(), i1 = axes_[1].history().begin(),
         i2 = axes_[2].history().begin();
    for (size_t i = 0; i < n; ++i, ++i0, ++i1, ++i2) s0 += *i0, s1 += *i1, s2 += *i2;
    const double count = static_cast<double>(n);
    axes_[0].set_mean(s0 / count), axes_[1].set_mean(s1 / count), axes_[2].set_mean(s2 / count);
  }

  void estimate() {
    bool together = axes_[0].size() == axes_[1].size() && axes_[1].size() == axes_[2].size() &&
                    axes_[0].order() == axes_[1].order() && axes_[1].order() == axes_[2].order();
    for (const BurgAxis& a : axes_) together = together && a.estimable();
    if (!together) {
      for (BurgAxis& a : axes_)
        if (const auto* c = a.centred_window())
          a.set_coefficients(burg(c->data(), static_cast<int>(c->size()), a.order()).coefficients);
      return;
    }
    // Centred as each axis centres its copy, read from the windows themselves.
    std::array<BurgResult, 3> r =
        burg3_centred({&axes_[0].history(), &axes_[1].history(), &axes_[2].history()},
                      {axes_[0].mean(), axes_[1].mean(), axes_[2].mean()}, axes_[0].order());
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
