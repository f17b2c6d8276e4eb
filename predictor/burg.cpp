#include "predictor/burg.hpp"

#include <stdexcept>

namespace sg::predictor {
namespace {

/// The two sums of eq. 30 for the next stage: numerator sum e_f(n) e_b(n-1) and denominator
/// sum e_f(n)^2 + e_b(n-1)^2 (without eq. 30's factor -2).
struct StageSums {
  double num = 0;
  double den = 0;
};

/// Stage 1's sums of eq. 30 over n = 1 .. N-1, with e_0^f = e_0^b = x (eq. 33, 34; burg.md's
/// "start").
StageSums first_stage_sums(const double* f, const double* b, int n) {
  StageSums s;
  for (int i = 1; i < n; ++i) {
    s.num += f[i] * b[i - 1];
    s.den += f[i] * f[i] + b[i - 1] * b[i - 1];
  }
  return s;
}

/// eq. 30: r_k = -2 num / den; 0 when den is below 1e-12 of twice the signal's energy: nothing
/// is left to model (burg.md, traps: a constant signal would give 0/0).
double reflection(const StageSums& s, double energy) {
  double r = 0;
  if (s.den > 1e-12 * 2 * energy && s.den > 0) r = -2 * s.num / s.den;  // else: nothing to model
  return r;
}

/// eq. 29: a_k(i) = a_{k-1}(i) + r a_{k-1}(k-i) for i < k, a_k(k) = r; in place, from both ends.
void update_coefficients(std::vector<double>& a, double r, int k) {
  for (int i = 0, j = k - 2; i <= j; ++i, --j) {
    const double ai = a[static_cast<size_t>(i)], aj = a[static_cast<size_t>(j)];
    a[static_cast<size_t>(i)] = ai + r * aj;
    if (i != j) a[static_cast<size_t>(j)] = aj + r * ai;
  }
  a.push_back(r);
}

/// Stage k's error update, eq. 31-32 in burg.md's (corrected) form e_f'(n) = e_f(n) + r e_b(n-1),
/// e_b'(n) = e_b(n-1) + r e_f(n), for n = N-1 down to k (b[n-1] is still the previous stage's
/// when b[n] is written), and stage k+1's sums of eq. 30 in the same pass: f[n+1] b[n] once b[n]
/// is new. Returns those sums.
StageSums next_stage(double* f, double* b, int n, int k, double r) {
  StageSums s;
  {
    const double fi = f[n - 1], bi = b[n - 2];  // the top: no f[i+1] yet
    f[n - 1] = fi + r * bi;
    b[n - 1] = bi + r * fi;
  }
  // Two partial sums each, so consecutive additions do not wait on each other.
  double num2 = 0, den2 = 0;
  int i = n - 2;
  for (; i - 1 >= k; i -= 2) {
    const double f0 = f[i], b0 = b[i - 1], f1 = f[i - 1], b1 = b[i - 2];
    const double f0n = f0 + r * b0, b0n = b0 + r * f0;
    const double f1n = f1 + r * b1, b1n = b1 + r * f1;
    s.num += f[i + 1] * b0n;
    s.den += f[i + 1] * f[i + 1] + b0n * b0n;
    num2 += f0n * b1n;
    den2 += f0n * f0n + b1n * b1n;
    f[i] = f0n, b[i] = b0n, f[i - 1] = f1n, b[i - 1] = b1n;
  }
  for (; i >= k; --i) {
    const double fi = f[i], bi = b[i - 1];
    const double f_new = fi + r * bi, b_new = bi + r * fi;
    s.num += f[i + 1] * b_new;
    s.den += f[i + 1] * f[i + 1] + b_new * b_new;
    f[i] = f_new, b[i] = b_new;
  }
  s.num += num2;
  s.den += den2;
  return s;
}

}  // namespace

BurgResult burg(const double* x, int n, int order) {
  if (order < 1 || n <= order)
    throw std::invalid_argument("burg: needs more samples than the order");
  // Forward and backward errors, reused between calls (the predictor calls this every sample).
  thread_local std::vector<double> f_buffer, b_buffer;
  f_buffer.assign(x, x + n);  // eq. 33, 34: e_0^f = e_0^b = x
  b_buffer.assign(x, x + n);
  double* const f = f_buffer.data();  // plain pointers: no thread-local lookups in the loops
  double* const b = b_buffer.data();
  BurgResult out;
  out.reflection_coeffs.reserve(static_cast<size_t>(order));
  out.error_power.reserve(static_cast<size_t>(order) + 1);
  double energy = 0;
  for (int i = 0; i < n; ++i) energy += x[i] * x[i];
  double e = energy / n;  // E_0
  out.error_power.push_back(e);
  StageSums sums = first_stage_sums(f, b, n);
  std::vector<double>& a = out.coefficients;
  a.reserve(static_cast<size_t>(order));
  for (int k = 1; k <= order; ++k) {
    const double r = reflection(sums, energy);
    update_coefficients(a, r, k);
    e *= (1 - r * r);  // E_k = E_{k-1} (1 - r_k^2)
    out.reflection_coeffs.push_back(r);
    out.error_power.push_back(e);
    if (k == order) break;  // the last stage's errors and sums would not be used
    sums = next_stage(f, b, n, k, r);
  }
  return out;
}

double predict_next(const std::vector<double>& a, const double* history, int size) {
  double s = 0;
  const int p = static_cast<int>(a.size());
  for (int k = 1; k <= p && k <= size; ++k) s -= a[static_cast<size_t>(k - 1)] * history[size - k];
  return s;
}

}  // namespace sg::predictor
