// Burg's method against Octave's arburg, and the predictor's behaviour with known answers.

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <fstream>
#include <random>
#include <sstream>

#include "predictor/burg.hpp"
#include "predictor/trajectory_predictor.hpp"

namespace sg::predictor {
namespace {

struct Reference {
  std::string name;
  int order = 0;
  std::vector<double> x, a, k;
  double v = 0;
};

std::vector<Reference> load_reference() {
  std::ifstream file(std::string(SG_SOURCE_DIR) + "/tests/fixtures/burg/arburg_reference.txt");
  std::vector<Reference> out;
  std::string line;
  auto numbers = [](std::istringstream& in) {
    std::vector<double> v;
    double d;
    while (in >> d) v.push_back(d);
    return v;
  };
  while (std::getline(file, line)) {
    std::istringstream in(line);
    std::string tag;
    in >> tag;
    if (tag == "signal") {
      out.emplace_back();
      int n;
      in >> out.back().name >> n >> out.back().order;
    } else if (tag == "x") {
      out.back().x = numbers(in);
    } else if (tag == "a") {
      out.back().a = numbers(in);
    } else if (tag == "k") {
      out.back().k = numbers(in);
    } else if (tag == "v") {
      in >> out.back().v;
    }
  }
  return out;
}

// Coefficients, reflection coefficients and error power equal Octave's arburg to 1e-9 on noisy
// signals (tests/fixtures/burg, with the script that made them).
TEST(Burg, MatchesOctavesArburg) {
  const auto references = load_reference();
  ASSERT_EQ(references.size(), 5u);
  for (const Reference& r : references) {
    const BurgResult b = burg(r.x.data(), static_cast<int>(r.x.size()), r.order);
    ASSERT_EQ(b.coefficients.size() + 1, r.a.size()) << r.name;
    EXPECT_DOUBLE_EQ(r.a[0], 1.0);
    for (int i = 0; i < r.order; ++i) {
      EXPECT_NEAR(b.coefficients[static_cast<size_t>(i)], r.a[static_cast<size_t>(i + 1)], 1e-9)
          << r.name << " a" << i + 1;
      EXPECT_NEAR(b.reflection_coeffs[static_cast<size_t>(i)], r.k[static_cast<size_t>(i)], 1e-9)
          << r.name << " k" << i + 1;
    }
    EXPECT_NEAR(b.error_power.back() / r.v, 1.0, 1e-9) << r.name;
  }
}

// The three-axis Burg model (three windows summed and estimated in one pass, the three forecasts
// in one loop) is three one-axis models, bit for bit: through measurements, an occlusion's
// fed-back samples, the gap replaced by its line, and a window that has filled and slides.
TEST(Burg, TrajectoryModelIsThreeAxisModelsBitForBit) {
  BurgParams p;
  p.order = 6;
  p.window = 60;
  const auto three = make_burg_trajectory({p, p, p});
  std::array<std::unique_ptr<AxisModel>, 3> one{make_burg_axis(p), make_burg_axis(p),
                                                make_burg_axis(p)};
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.002);
  for (int k = 0; k < 150; ++k) {
    const bool measured = k % 40 < 34;  // six samples hidden in every forty
    const std::array<double, 3> v{0.4 + 0.2 * std::cos(0.07 * k) + noise(rng),
                                  0.2 * std::sin(0.07 * k) + noise(rng), 0.1 + noise(rng)};
    if (measured && k % 40 == 0 && k > 0) {  // back: the hidden samples become a line
      std::array<std::vector<double>, 3> line;
      for (size_t a = 0; a < 3; ++a) {
        line[a] = {v[a] - 0.01, v[a] - 0.005};
        one[a]->replace_newest(line[a]);
      }
      three->replace_newest(line);
    }
    three->push(v, measured);
    for (size_t a = 0; a < 3; ++a) one[a]->push(v[a], measured);
    const std::array<std::vector<double>, 3> f = three->forecast(16);
    for (size_t a = 0; a < 3; ++a) {
      SCOPED_TRACE(testing::Message() << "sample " << k << ", axis " << a);
      ASSERT_EQ(f[a], one[a]->forecast(16));  // exact: bit for bit
      ASSERT_EQ(f[a].size(), 16u);
    }
  }
}

// burg3 on three signals (a circle's x and y, noise) is burg on each, bit for bit: reflection
// coefficients, coefficients and error powers, for short and long windows and several orders.
TEST(Burg, ThreeAxesInOnePassAreEachAxisBitForBit) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.002);
  for (const int n : {16, 97, 480}) {
    for (const int order : {1, 5, 12}) {
      std::vector<double> x(static_cast<size_t>(n)), y(x.size()), z(x.size());
      for (int i = 0; i < n; ++i) {
        x[static_cast<size_t>(i)] = 0.3 * std::cos(0.1 * i) + noise(rng);
        y[static_cast<size_t>(i)] = 0.3 * std::sin(0.1 * i) + noise(rng);
        z[static_cast<size_t>(i)] = noise(rng);
      }
      const std::array<BurgResult, 3> three = burg3({x.data(), y.data(), z.data()}, n, order);
      const std::vector<double>* axes[3] = {&x, &y, &z};
      for (size_t a = 0; a < 3; ++a) {
        SCOPED_TRACE(testing::Message() << "n " << n << ", order " << order << ", axis " << a);
        const BurgResult one = burg(axes[a]->data(), n, order);
        EXPECT_EQ(three[a].reflection_coeffs, one.reflection_coeffs);  // exact: bit for bit
        EXPECT_EQ(three[a].coefficients, one.coefficients);
        EXPECT_EQ(three[a].error_power, one.error_power);
      }
    }
  }
  EXPECT_THROW(burg3({nullptr, nullptr, nullptr}, 5, 5), std::invalid_argument);
  const std::deque<double> w5(5, 1.0), w6(6, 1.0);
  EXPECT_THROW(burg3_centred({&w5, &w5, &w6}, {0, 0, 0}, 2), std::invalid_argument);
  EXPECT_THROW(burg3_centred({&w5, &w5, &w5}, {0, 0, 0}, 5), std::invalid_argument);
}

// burg3_centred of three windows and their means is burg of each centred copy, bit for bit.
TEST(Burg, ThreeCentredWindowsAreEachCentredAxisBitForBit) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 0.002);
  std::array<std::deque<double>, 3> w;
  for (int i = 0; i < 97; ++i) {
    w[0].push_back(0.45 + 0.3 * std::cos(0.1 * i) + noise(rng));
    w[1].push_back(-0.2 + 0.3 * std::sin(0.1 * i) + noise(rng));
    w[2].push_back(0.1 + noise(rng));
  }
  const std::array<double, 3> means{0.45, -0.2, 0.1};
  const auto three = burg3_centred({&w[0], &w[1], &w[2]}, means, 8);
  for (size_t a = 0; a < 3; ++a) {
    std::vector<double> centred(w[a].begin(), w[a].end());
    for (double& v : centred) v -= means[a];
    const BurgResult one = burg(centred.data(), static_cast<int>(centred.size()), 8);
    EXPECT_EQ(three[a].coefficients, one.coefficients) << a;  // exact: bit for bit
    EXPECT_EQ(three[a].reflection_coeffs, one.reflection_coeffs) << a;
  }
}

// The prediction error power never increases with the order (the guard against the paper's sign
// error in eq. 30-32, which breaks every order above 1).
TEST(Burg, ErrorPowerNeverIncreasesWithOrder) {
  for (const Reference& r : load_reference()) {
    const BurgResult b = burg(r.x.data(), static_cast<int>(r.x.size()),
                              std::min(20, static_cast<int>(r.x.size()) - 1));
    for (size_t k = 1; k < b.error_power.size(); ++k) {
      EXPECT_LE(b.error_power[k], b.error_power[k - 1] * (1 + 1e-12)) << r.name << " order " << k;
      EXPECT_LE(std::abs(b.reflection_coeffs[k - 1]), 1.0) << r.name;
    }
  }
}

// A noise-free sinusoid is an AR(2) process, x_n = 2 cos(w) x_{n-1} - x_{n-2}: order 2 forecasts
// it exactly 16 steps ahead. Burg's r_1 is exactly -cos(w) when the window's N - 1 lag products
// span whole periods (here 3 periods of 37 samples, N = 112); r_2 = 1 then follows exactly, as the
// order-1 forward and backward errors of a sinusoid are each other's negatives.
TEST(Burg, ForecastsANoiseFreeAr2Exactly) {
  BurgParams p;
  p.order = 2;
  p.window = 112;
  p.remove_mean = false;
  auto axis = make_burg_axis(p);
  const double w = 2 * M_PI / 37;
  for (int n = 0; n < 112; ++n) axis->push(std::cos(w * n + 0.4), true);
  const auto f = axis->forecast(16);
  for (int h = 1; h <= 16; ++h)
    EXPECT_NEAR(f[static_cast<size_t>(h - 1)], std::cos(w * (111 + h) + 0.4), 1e-9) << h;
  const std::vector<double> x = [&] {
    std::vector<double> v;
    for (int n = 0; n < 112; ++n) v.push_back(std::cos(w * n + 0.4));
    return v;
  }();
  const BurgResult b = burg(x.data(), 112, 2);
  EXPECT_NEAR(b.coefficients[0], -2 * std::cos(w), 1e-12);
  EXPECT_NEAR(b.coefficients[1], 1.0, 1e-12);
}

// A constant signal (a still ball, or Z of a horizontal circle) gives finite output: itself.
TEST(Burg, ConstantSignalIsFinite) {
  const std::vector<double> still(100, 0.45);
  const BurgResult b = burg(still.data(), 100, 12);
  for (double a : b.coefficients) EXPECT_TRUE(std::isfinite(a));
  for (bool remove_mean : {true, false}) {
    BurgParams p;
    p.remove_mean = remove_mean;
    auto axis = make_burg_axis(p);
    for (int i = 0; i < 100; ++i) axis->push(0.45, true);
    for (double v : axis->forecast(16)) EXPECT_NEAR(v, 0.45, 1e-12);
  }
}

// Offline-trained coefficients are kept until the window holds online_after samples, then Burg's
// own estimate replaces them: a wrong AR(2) forecast (a_1 = 2, a_2 = -1: a straight line) shows
// which coefficients are in use on a noise-free sinusoid.
TEST(Burg, OfflineCoefficientsHoldUntilOnlineAfter) {
  BurgParams p;
  p.order = 2;
  p.remove_mean = false;
  p.initial_coefficients = {-2.0, 1.0};  // eq. 27's sign: x[n] = -a_1 x[n-1] - a_2 x[n-2]
  p.online_after = 40;
  auto axis = make_burg_axis(p);
  const double w = 2 * M_PI / 24;
  auto wave = [w](int n) { return std::sin(w * n); };
  for (int n = 0; n < 39; ++n) axis->push(wave(n), true);
  // Still the straight line through the last two samples.
  EXPECT_NEAR(axis->forecast(1)[0], 2 * wave(38) - wave(37), 1e-12);
  axis->push(wave(39), true);
  // Burg on a pure sinusoid finds about x[n] = 2 cos(w) x[n-1] - x[n-2]: far nearer the next
  // sample than the straight line (whose error is about w^2 |x|, 0.05 here).
  const double line_error = std::abs(2 * wave(39) - wave(38) - wave(40));
  EXPECT_GT(line_error, 0.04);
  EXPECT_LT(std::abs(axis->forecast(1)[0] - wave(40)), 0.2 * line_error);
}

PredictorParams params_4hz() {
  PredictorParams p;
  p.burg.window = 240;
  return p;
}

Eigen::Vector3d circle(double t) {
  return {0.45 + 0.15 * std::cos(2 * M_PI * t / 60), 0.15 * std::sin(2 * M_PI * t / 60), 0.10};
}

constexpr int64_t kT0 = 1'700'000'000'000'000;

// The gate: while tracking, one measurement 30 mm off (a partly hidden ball's centroid) is taken
// as not seen, so the forecast is the same as without it; a ball that really jumped is believed
// once the measurements have disagreed for longer than the patience.
TEST(Predictor, GateDropsOutliersButNotARealJump) {
  PredictorParams p = params_4hz();
  TrajectoryPredictor gated(p), clean(p);
  std::vector<Forecast> with_outlier, without;
  int64_t k = 0;
  auto at = [](int64_t i) { return kT0 + i * 250'000 / 8; };  // 32 Hz
  for (; k < 8 * 120; ++k) {                                  // two minutes of tracking
    const Measurement m{at(k), true, circle(static_cast<double>(at(k) - kT0) * 1e-6)};
    gated.add(m);
    clean.add(m);
  }
  Measurement outlier{at(k), true, circle(static_cast<double>(at(k) - kT0) * 1e-6)};
  outlier.position.x() += 0.030;
  with_outlier = gated.add(outlier);
  without = clean.add({at(k), false, Eigen::Vector3d::Zero()});
  EXPECT_EQ(gated.gated(), 1u);
  ASSERT_EQ(with_outlier.size(), without.size());
  for (size_t i = 0; i < with_outlier.size(); ++i) {
    EXPECT_LT((with_outlier[i].positions.back() - without[i].positions.back()).norm(), 1e-12);
  }
  // A jump of 50 mm that stays: gated for the patience (0.5 s), then followed.
  const Eigen::Vector3d jump(0.05, 0, 0);
  int followed_after = -1;
  for (int i = 1; i <= 64 && followed_after < 0; ++i) {
    const int64_t t = at(k + i);
    for (const Forecast& f : gated.add({t, true, circle((t - kT0) * 1e-6) + jump})) {
      if (f.status == TrackStatus::kTracking &&
          (f.sample - (circle((f.utime - kT0) * 1e-6) + jump)).norm() < 0.02) {
        followed_after = i;
      }
    }
  }
  EXPECT_GT(followed_after, 8);   // not before the patience of 0.5 s (16 measurements) ...
  EXPECT_LT(followed_after, 40);  // ... but soon after
  EXPECT_GT(gated.gated(), 10u);
}

// Occlusion: fed-back samples carry the track (status OCCLUDED, counted), stay near the truth,
// and the track recovers when the ball is seen again; after max_gap (24) fed-back samples it is
// lost.
TEST(Predictor, OcclusionFeedbackRecoveryAndLoss) {
  ASSERT_EQ(params_4hz().max_gap, 24);
  TrajectoryPredictor predictor(params_4hz());
  int64_t k = 0;
  auto step = [&](bool visible) {
    const double t = static_cast<double>(k) * 0.25;
    auto out = predictor.add({kT0 + k * 250'000, visible, circle(t)});
    ++k;
    return out;
  };
  for (int i = 0; i < 300; ++i) step(true);
  double worst = 0;
  for (int i = 1; i <= 10; ++i) {
    const auto f = step(false);
    ASSERT_EQ(f.size(), 1u);
    EXPECT_EQ(f[0].status, TrackStatus::kOccluded);
    EXPECT_EQ(f[0].occluded_samples, i);
    worst = std::max(worst, (f[0].positions[0] - circle(static_cast<double>(k) * 0.25)).norm());
  }
  EXPECT_LT(worst, 0.002) << "noise-free circle through a 2.5 s occlusion";
  auto back = step(true);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].status, TrackStatus::kTracking);
  EXPECT_EQ(back[0].occluded_samples, 0);
  EXPECT_LT((back[0].positions[0] - circle(static_cast<double>(k) * 0.25)).norm(), 0.002);
  for (int i = 0; i < 24; ++i) {
    const auto f = step(false);
    ASSERT_FALSE(f.empty());
    EXPECT_EQ(f.back().status, TrackStatus::kOccluded) << i;
  }
  const auto lost = step(false);
  ASSERT_FALSE(lost.empty());
  EXPECT_EQ(lost.back().status, TrackStatus::kLost);
  EXPECT_EQ(predictor.status(), TrackStatus::kLost);
  const auto again = step(true);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].status, TrackStatus::kTracking);
  // The restarted model claims no more than the prior (5 mm a sample of horizon), where the old
  // one was sure to a fraction of a millimetre.
  const double prior = PredictorParams{}.error.prior_sigma;
  for (int h : {1, 7, 16})
    EXPECT_GE(again[0].sigma[static_cast<size_t>(h - 1)].minCoeff(), prior * h - 1e-12) << h;
}

// Every forecast carries a sigma per point: the error model's at h samples past a measurement
// (h + k for a forecast made k samples into an occlusion), from scores of the predictor's own
// forecasts on a circle with 2 mm of noise the measurements say they have: the sigma is of the
// error against the true circle, a fraction of a millimetre at h = 1, and it grows with h. (A
// window of 400 scores: over the default 60 the mean of e^2 - r^2 alone scatters by 0.18 r^2,
// some 1.2 mm of sigma, and a build's rounding decides which side of 1.5 mm it lands.)
TEST(Predictor, ForecastsCarryTheirOwnErrorEstimate) {
  PredictorParams p = params_4hz();
  p.error.window = 400;
  TrajectoryPredictor predictor(p);
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0, 0.002);
  int64_t k = 0;
  auto step = [&](bool visible) {
    const double t = static_cast<double>(k) * 0.25;
    const Eigen::Vector3d seen = circle(t) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    return predictor.add({kT0 + k++ * 250'000, visible, seen, Eigen::Vector3d::Constant(0.002)});
  };
  for (int i = 0; i < 1200; ++i) step(true);
  const auto f = step(true);
  ASSERT_EQ(f.size(), 1u);
  ASSERT_EQ(f[0].sigma.size(), f[0].positions.size());
  EXPECT_GT(predictor.error().scores(1), 1000);
  for (size_t h = 0; h < f[0].sigma.size(); ++h)
    EXPECT_EQ(f[0].sigma[h], predictor.error().sigma(static_cast<int>(h) + 1)) << h;
  EXPECT_LT(f[0].sigma[0].maxCoeff(), 0.0015);
  EXPECT_GT(f[0].sigma[15].x(), f[0].sigma[0].x());
  step(false);
  const auto hidden = step(false);
  ASSERT_EQ(hidden.size(), 1u);
  ASSERT_EQ(hidden[0].occluded_samples, 2);
  EXPECT_EQ(hidden[0].sigma[0], predictor.error().sigma(3));
}

// After an occlusion of g samples, the forecasts made on the first `after_gap` (2) measured
// samples publish the sigma of a forecast still g samples inside it, sigma(h + g): their history's
// newest samples are the line across the gap, not measurements. The third publishes sigma(h).
TEST(Predictor, ForecastsJustAfterAGapCarryTheGapsSigma) {
  PredictorParams p = params_4hz();
  TrajectoryPredictor predictor(p);
  ASSERT_EQ(p.after_gap, 2);
  int64_t k = 0;
  auto step = [&](bool visible) {
    const double t = static_cast<double>(k) * 0.25;
    return predictor.add({kT0 + k++ * 250'000, visible, circle(t)});
  };
  for (int i = 0; i < 400; ++i) step(true);
  for (int i = 0; i < 5; ++i) step(false);
  for (int after = 1; after <= 3; ++after) {
    const auto f = step(true);
    ASSERT_EQ(f.size(), 1u);
    ASSERT_EQ(f[0].occluded_samples, 0);
    const int unseen = after <= 2 ? 5 : 0;
    for (int h : {1, 7, 16})
      EXPECT_EQ(f[0].sigma[static_cast<size_t>(h - 1)], predictor.error().sigma(h + unseen))
          << "sample " << after << " after the gap, h = " << h;
  }
}

// 30 Hz measurements become samples every 0.25 s exactly, linearly interpolated on utime.
TEST(Predictor, ResamplesIrregularInputOntoThePeriod) {
  PredictorParams p = params_4hz();
  p.model = Model::kHold;  // the forecast is the newest sample itself
  TrajectoryPredictor predictor(p);
  std::vector<Forecast> samples;
  for (int i = 0; i <= 300; ++i) {  // 10 s at 30 Hz, with jitter
    const int64_t utime = kT0 + i * 33'333 + (i % 3) * 1'000;
    for (const auto& f :
         predictor.add({utime, true, circle(static_cast<double>(utime - kT0) * 1e-6)}))
      samples.push_back(f);
  }
  ASSERT_EQ(samples.size(), 40u);
  for (size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(samples[i].utime, kT0 + static_cast<int64_t>(i) * 250'000);
    // Linear interpolation of a circle over 33 ms: within the chord's sag (microns).
    EXPECT_LT((samples[i].positions[0] - circle(static_cast<double>(i) * 0.25)).norm(), 2e-6) << i;
  }
}

// NaN and infinite positions, time going backwards and a repeated utime are rejected and counted;
// the state is untouched.
TEST(Predictor, RejectsBadInput) {
  TrajectoryPredictor predictor(params_4hz());
  EXPECT_EQ(predictor.add({kT0, true, circle(0)}).size(), 1u);
  const double nan = std::nan("");
  EXPECT_TRUE(predictor.add({kT0 + 250'000, true, {nan, 0, 0}}).empty());
  EXPECT_TRUE(predictor.add({kT0 + 250'000, true, {INFINITY, 0, 0}}).empty());
  EXPECT_TRUE(predictor.add({kT0 - 1, true, circle(0)}).empty());
  EXPECT_TRUE(predictor.add({kT0, true, circle(0)}).empty());
  EXPECT_EQ(predictor.rejected(), 4u);
  const auto next = predictor.add({kT0 + 250'000, true, circle(0.25)});
  ASSERT_EQ(next.size(), 1u);
  EXPECT_EQ(next[0].utime, kT0 + 250'000);
  EXPECT_TRUE(predictor.add({kT0 + 250'000 + 1, false, {nan, nan, nan}}).empty())
      << "an invisible NaN is fine";
  EXPECT_EQ(predictor.rejected(), 4u);
}

// The baselines behind the same interface: Kalman follows a line exactly, hold holds.
TEST(Predictor, Baselines) {
  PredictorParams p = params_4hz();
  p.model = Model::kKalman;
  TrajectoryPredictor kalman(p);
  Forecast last;
  for (int i = 0; i < 200; ++i) {
    for (const auto& f :
         kalman.add({kT0 + i * 250'000, true, Eigen::Vector3d(0.01 * i * 0.25, 0, 0)}))
      last = f;
  }
  EXPECT_NEAR(last.positions[15].x(), 0.01 * (199 + 16) * 0.25, 1e-4);
  EXPECT_EQ(model_from_name("hold"), Model::kHold);
  EXPECT_THROW(model_from_name("lstm"), std::invalid_argument);
}

}  // namespace
}  // namespace sg::predictor
