#include "predictor/burg.hpp"

#include <stdexcept>

namespace sg::predictor {

BurgResult burg(const double* x, int n, int order) {
  if (order < 1 || n <= order)
    throw std::invalid_argument("burg: needs more samples than the order");
  // Forward and backward errors, reused between calls (the predictor calls this every sample).
  thread_local std::vector<double> f_buffer, b_buffer;
  f_buffer.assign(x, x + n);
  b_buffer.assign(x, x + n);
  double* const f = f_buffer.data();  // plain pointers: no thread-local lookups in the loops
  double* const b = b_buffer.data();
  BurgResult out;
  out.reflection_coeffs.reserve(static_cast<size_t>(order));
  out.error_power.reserve(static_cast<size_t>(order) + 1);
  double energy = 0;
  for (int i = 0; i < n; ++i) energy += x[i] * x[i];
  double e = energy / n;
  out.error_power.push_back(e);
  // Stage 1's sums over n = 1 .. N-1 of e_f(n) e_b(n-1) and e_f(n)^2 + e_b(n-1)^2.
  double num = 0, den = 0;
  for (int i = 1; i < n; ++i) {
    num += f[i] * b[i - 1];
    den += f[i] * f[i] + b[i - 1] * b[i - 1];
  }
  std::vector<double>& a = out.coefficients;
  a.reserve(static_cast<size_t>(order));
  for (int k = 1; k <= order; ++k) {
    double r = 0;
    if (den > 1e-12 * 2 * energy && den > 0) r = -2 * num / den;  // else: nothing left to model
    // eq. 29: a_k(i) = a_{k-1}(i) + r a_{k-1}(k-i), a_k(k) = r (in place, from both ends)
    for (int i = 0, j = k - 2; i <= j; ++i, --j) {
      const double ai = a[static_cast<size_t>(i)], aj = a[static_cast<size_t>(j)];
      a[static_cast<size_t>(i)] = ai + r * aj;
      if (i != j) a[static_cast<size_t>(j)] = aj + r * ai;
    }
    a.push_back(r);
    e *= (1 - r * r);
    out.reflection_coeffs.push_back(r);
    out.error_power.push_back(e);
    if (k == order) break;  // the last stage's errors and sums would not be used
    // Update the errors downwards (b[i-1] is still the previous stage's when b[i] is written) and
    // sum the next stage's terms in the same pass: f[i+1] b[i] once b[i] is new.
    num = den = 0;
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
      num += f[i + 1] * b0n;
      den += f[i + 1] * f[i + 1] + b0n * b0n;
      num2 += f0n * b1n;
      den2 += f0n * f0n + b1n * b1n;
      f[i] = f0n, b[i] = b0n, f[i - 1] = f1n, b[i - 1] = b1n;
    }
    for (; i >= k; --i) {
      const double fi = f[i], bi = b[i - 1];
      const double f_new = fi + r * bi, b_new = bi + r * fi;
      num += f[i + 1] * b_new;
      den += f[i + 1] * f[i + 1] + b_new * b_new;
      f[i] = f_new, b[i] = b_new;
    }
    num += num2;
    den += den2;
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
