#include "vision/ball_fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

namespace sg::vision {

namespace {

constexpr double kMaxCoordinate = 1e9;  // px: no image is a billion pixels wide

bool usable(const cv::Point2d& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::abs(p.x) <= kMaxCoordinate &&
         std::abs(p.y) <= kMaxCoordinate;
}

/// A number in [0, 4) increasing with the angle of (x, y) around the origin (no trigonometry).
double pseudo_angle(double x, double y) {
  const double l1 = std::abs(x) + std::abs(y);
  if (l1 == 0) return 0;
  const double t = y / l1;  // -1..1
  return x >= 0 ? (y >= 0 ? t : 4 + t) : 2 - t;
}

/// atan2(y, x) / (2 pi) + 1/2, in [0, 1], within 2e-6 (a minimax polynomial for atan on [0, 1]).
double turn_fraction(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y), hi = std::max(ax, ay);
  if (hi == 0) return 0.5;
  const double z = std::min(ax, ay) / hi, z2 = z * z;
  double a =
      z * (0.99997726 +
           z2 * (-0.33262347 +
                 z2 * (0.19354346 + z2 * (-0.11643287 + z2 * (0.05265332 + z2 * -0.01172120)))));
  if (ay > ax) a = M_PI / 2 - a;
  if (x < 0) a = M_PI - a;
  if (y < 0) a = -a;
  return a / (2 * M_PI) + 0.5;
}

}  // namespace

int arc_sector(double dx, double dy) {
  return std::clamp(static_cast<int>(turn_fraction(dy, dx) * kArcSectors), 0, kArcSectors - 1);
}

void append_edge_points(const cv::Mat& mask, cv::Point origin, const cv::Rect& valid,
                        std::vector<cv::Point2d>& out) {
  if (mask.empty()) return;
  if (mask.type() != CV_8UC1) throw std::invalid_argument("append_edge_points: mask not CV_8UC1");
  const auto inside = [&valid](int x, int y) { return valid.contains(cv::Point(x, y)); };
  for (int r = 0; r < mask.rows; ++r) {
    const uint8_t* row = mask.ptr<uint8_t>(r);
    const uint8_t* up = r > 0 ? mask.ptr<uint8_t>(r - 1) : nullptr;
    const uint8_t* down = r + 1 < mask.rows ? mask.ptr<uint8_t>(r + 1) : nullptr;
    const int y = origin.y + r;
    for (int c = 0; c < mask.cols; ++c) {
      if (!row[c]) continue;
      const int x = origin.x + c;
      if (!(c > 0 && row[c - 1]) && inside(x - 1, y)) out.emplace_back(x - 0.5, y);
      if (!(c + 1 < mask.cols && row[c + 1]) && inside(x + 1, y)) out.emplace_back(x + 0.5, y);
      if (!(up && up[c]) && inside(x, y - 1)) out.emplace_back(x, y - 0.5);
      if (!(down && down[c]) && inside(x, y + 1)) out.emplace_back(x, y + 0.5);
    }
  }
}

BallFitter::BallFitter(size_t max_points) : max_points_(std::max<size_t>(max_points, 3)) {
  xs_.resize(max_points_);
  ys_.resize(max_points_);
  xf_.resize(max_points_);
  yf_.resize(max_points_);
  order_.resize(max_points_);
  inliers_.resize(max_points_);
}

size_t BallFitter::gather(const std::vector<cv::Point2d>& edge) {
  size_t total = 0;
  double sx = 0, sy = 0;
  for (const cv::Point2d& p : edge) {
    if (!usable(p)) continue;
    ++total, sx += p.x, sy += p.y;
  }
  if (total == 0) return 0;
  offset_ = {sx / static_cast<double>(total), sy / static_cast<double>(total)};
  const size_t n = std::min(total, max_points_);
  // Usable point v is kept when floor(v n / total) steps: n points spread evenly over `total`.
  size_t v = 0, kept = 0;
  for (const cv::Point2d& p : edge) {
    if (!usable(p)) continue;
    if ((v * n) / total != ((v + 1) * n) / total && kept < n) {
      xs_[kept] = p.x - offset_.x;
      ys_[kept] = p.y - offset_.y;
      xf_[kept] = static_cast<float>(xs_[kept]);
      yf_[kept] = static_cast<float>(ys_[kept]);
      ++kept;
    }
    ++v;
  }
  return kept;
}

void BallFitter::order_by_angle(size_t n) {
  for (size_t i = 0; i < n; ++i) order_[i] = {pseudo_angle(xs_[i], ys_[i]), uint32_t(i)};
  std::sort(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(n));
}

double BallFitter::score(const Circle& c, size_t n, const BallFitParams& p, double hint) const {
  // e = (d^2 - r^2) / (2 r) is d - r to within a factor 1 + e / (2 r) in the band |e| < tol, and
  // needs no square root; float, in 8 independent lanes, lets the compiler vectorise the loop.
  const float cx = static_cast<float>(c.x), cy = static_cast<float>(c.y);
  const float r2 = static_cast<float>(c.r * c.r);
  const float inv = static_cast<float>(1 / (2 * c.r * p.inlier_tolerance));
  const float out2 = static_cast<float>((c.r + p.outside_tolerance) * (c.r + p.outside_tolerance));
  const float penalty = static_cast<float>(p.outside_penalty);
  const float* xs = xf_.data();
  const float* ys = yf_.data();
  const auto term = [&](size_t i) {
    const float dx = xs[i] - cx, dy = ys[i] - cy, d2 = dx * dx + dy * dy;
    const float e = (d2 - r2) * inv, t = 1 - e * e;
    return (t > 0 ? t : 0.0f) - (d2 > out2 ? penalty : 0.0f);
  };
  constexpr size_t kLanes = 8;
  std::array<float, kLanes> acc{};
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (size_t j = 0; j < kLanes; ++j) acc[j] += term(i + j);
  }
  double s = 0;
  for (; i < n; ++i) s += term(i);
  for (const float a : acc) s += a;
  if (hint > 0 && p.hint_scale > 0) {
    const double z = std::log(c.r / hint) / p.hint_scale;
    s -= p.hint_weight * static_cast<double>(n) * z * z;
  }
  return s;
}

bool BallFitter::best_hypothesis(size_t n, const BallFitParams& p, double hint,
                                 Circle& best) const {
  static constexpr std::array<size_t, 4> kDivisors = {3, 5, 8, 12};
  const int per_span = std::max(1, (p.iterations + 3) / 4);
  double best_score = -1e300;
  bool found = false;
  for (int h = 0; h < std::max(p.iterations, 1); ++h) {
    const size_t k = static_cast<size_t>(h / per_span) % kDivisors.size();
    const size_t s = std::max<size_t>(1, n / kDivisors[k]);
    // Starts spread over the order, staggered between spans.
    const size_t i = (static_cast<size_t>(h % per_span) * n / per_span + k * n / 7) % n;
    const auto at = [&](size_t j) { return order_[(i + j) % n].second; };
    const uint32_t a = at(0), b = at(s), q = at(2 * s);
    const double bx = xs_[b] - xs_[a], by = ys_[b] - ys_[a];
    const double cx = xs_[q] - xs_[a], cy = ys_[q] - ys_[a];
    const double det = 2 * (bx * cy - by * cx);
    if (det == 0) continue;
    const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    const double ux = (cy * b2 - by * c2) / det, uy = (bx * c2 - cx * b2) / det;
    const Circle c{xs_[a] + ux, ys_[a] + uy, std::sqrt(ux * ux + uy * uy)};
    if (!(c.r >= p.min_radius && c.r <= p.max_radius) || !std::isfinite(c.x + c.y)) continue;
    const double sc = score(c, n, p, hint);
    if (sc > best_score) best_score = sc, best = c, found = true;
  }
  return found;
}

size_t BallFitter::select_inliers(const Circle& c, size_t n, double tolerance) {
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    const double dx = xs_[i] - c.x, dy = ys_[i] - c.y, d = std::sqrt(dx * dx + dy * dy);
    if (std::abs(d - c.r) <= tolerance) inliers_[m++] = uint32_t(i);
  }
  return m;
}

bool BallFitter::kasa(Circle& c, size_t m) const {
  // Minimises sum (x^2 + y^2 + D x + E y + F)^2 around the inliers' mean (conditioning).
  double mx = 0, my = 0;
  for (size_t k = 0; k < m; ++k) mx += xs_[inliers_[k]], my += ys_[inliers_[k]];
  mx /= static_cast<double>(m), my /= static_cast<double>(m);
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < m; ++k) {
    const double x = xs_[inliers_[k]] - mx, y = ys_[inliers_[k]] - my;
    const Eigen::Vector3d row(x, y, 1.0);
    a += row * row.transpose();
    b -= row * (x * x + y * y);
  }
  const Eigen::Vector3d def = a.ldlt().solve(b);
  const double x0 = -def(0) / 2, y0 = -def(1) / 2, r2 = x0 * x0 + y0 * y0 - def(2);
  if (!def.allFinite() || !(r2 > 0)) return false;
  c = {mx + x0, my + y0, std::sqrt(r2)};
  return true;
}

bool BallFitter::gauss_newton(Circle& c, size_t m, int steps) const {
  for (int step = 0; step < steps; ++step) {
    // Normal equations J^T J delta = -J^T res with J_k = -(u_x, u_y, 1), u the unit radial vector,
    // so -J^T res = sum (u_x, u_y, 1) res.
    double sxx = 0, sxy = 0, syy = 0, sx = 0, sy = 0, rx = 0, ry = 0, rr = 0, count = 0;
    for (size_t k = 0; k < m; ++k) {
      const double dx = xs_[inliers_[k]] - c.x, dy = ys_[inliers_[k]] - c.y;
      const double d = std::sqrt(dx * dx + dy * dy);
      if (d < 1e-9) continue;
      const double ux = dx / d, uy = dy / d, res = d - c.r;
      sxx += ux * ux, sxy += ux * uy, syy += uy * uy, sx += ux, sy += uy, count += 1;
      rx += ux * res, ry += uy * res, rr += res;
    }
    Eigen::Matrix3d jtj;
    jtj << sxx, sxy, sx, sxy, syy, sy, sx, sy, count;
    jtj.diagonal() *= 1 + 1e-9;  // a touch of Levenberg-Marquardt damping
    const Eigen::Vector3d delta = jtj.ldlt().solve(Eigen::Vector3d(rx, ry, rr));
    if (!delta.allFinite()) return false;
    c.x += delta(0), c.y += delta(1), c.r += delta(2);
    if (delta.squaredNorm() < 1e-12) break;
  }
  return std::isfinite(c.x + c.y + c.r) && c.r > 0;
}

bool BallFitter::refine(Circle& c, size_t n, const BallFitParams& p) {
  for (int round = 0; round < std::max(p.refinements, 1); ++round) {
    const size_t m = select_inliers(c, n, p.inlier_tolerance);
    if (m < 3) return round > 0;
    Circle next = c;
    if (round == 0 && !kasa(next, m)) next = c;
    if (!gauss_newton(next, m, p.gauss_newton_steps)) return round > 0;
    if (!(next.r >= p.min_radius && next.r <= p.max_radius)) return round > 0;
    c = next;
  }
  return true;
}

uint64_t BallFitter::arc_of(double r) const {
  // A whole outline has at least 1 edge point per px of arc (4-neighbour midpoints: |cos| + |sin|
  // per px); half of that marks a sector seen, and a lone empty sector between two seen ones is
  // a gap of the pixel grid (a small circle's sectors hold one point or none), not of the arc.
  const double half = 0.5 * (2 * M_PI * r / kArcSectors);
  uint64_t arc = 0;
  for (int k = 0; k < kArcSectors; ++k) {
    if (sector_points_[static_cast<size_t>(k)] >= std::max(1.0, half)) arc |= uint64_t{1} << k;
  }
  arc |= std::rotl(arc, 1) & std::rotr(arc, 1);
  return arc;
}

BallFit BallFitter::describe(const Circle& c, size_t n, const BallFitParams& p) {
  BallFit f;
  f.points = static_cast<int>(n);
  f.centre = {c.x + offset_.x, c.y + offset_.y};
  f.radius = c.r;
  const int bins =
      std::clamp(static_cast<int>(2 * M_PI * c.r / std::max(p.support_bin, 1e-3)), 8, kMaxBins);
  std::fill(bins_.begin(), bins_.begin() + bins, uint8_t{0});
  sector_points_.fill(0);
  double sum2 = 0;
  for (size_t i = 0; i < n; ++i) {
    const double dx = xs_[i] - c.x, dy = ys_[i] - c.y;
    const double d = std::sqrt(dx * dx + dy * dy), e = d - c.r;
    f.outside += d > c.r + p.outside_tolerance;
    if (std::abs(e) > p.inlier_tolerance) continue;
    ++f.inliers, sum2 += e * e;
    const double t = turn_fraction(dy, dx);  // 0..1
    bins_[static_cast<size_t>(std::clamp(static_cast<int>(t * bins), 0, bins - 1))] = 1;
    uint16_t& k = sector_points_[static_cast<size_t>(  // arc_sector(dx, dy), t already known
        std::clamp(static_cast<int>(t * kArcSectors), 0, kArcSectors - 1))];
    k = static_cast<uint16_t>(std::min(k + 1, 65535));
  }
  int covered = 0;
  for (int b = 0; b < bins; ++b) covered += bins_[static_cast<size_t>(b)];
  f.support = static_cast<double>(covered) / bins;
  f.arc = arc_of(c.r);
  f.rms = f.inliers > 0 ? std::sqrt(sum2 / f.inliers) : 0.0;
  const double out_share = static_cast<double>(f.outside) / static_cast<double>(n);
  const double q = f.rms / p.confidence_rms_scale;
  f.confidence = (1 - std::exp(-f.support / p.confidence_support_scale)) * std::exp(-q * q / 2) *
                 std::exp(-out_share / p.confidence_outside_scale);
  f.ok = f.inliers >= std::max(p.min_inliers, 3);
  return f;
}

BallFit BallFitter::fit(const std::vector<cv::Point2d>& edge, const BallFitParams& params,
                        std::optional<double> radius_hint) {
  BallFit none;
  const size_t n = gather(edge);
  none.points = static_cast<int>(n);
  if (n < 3 || !(params.inlier_tolerance > 0)) return none;
  const double hint =
      radius_hint && std::isfinite(*radius_hint) && *radius_hint > 0 ? *radius_hint : 0.0;
  order_by_angle(n);
  Circle c;
  if (!best_hypothesis(n, params, hint, c) || !refine(c, n, params)) return none;
  return describe(c, n, params);
}

}  // namespace sg::vision
