#include "predictor/burg.hpp"

#include <stdexcept>

namespace sg::predictor {

BurgResult burg(const double* x, int n, int order) {
  if (order < 1 || n <= order)
    throw std::invalid_argument("burg: needs more samples than the order");
  std::vector<double> f(x, x + n), b(x, x + n);
  BurgResult out;
  double energy = 0;
  for (int i = 0; i < n; ++i) energy += x[i] * x[i];
  double e = energy / n;
  out.error_power.push_back(e);
  std::vector<double> a;
  for (int k = 1; k <= order; ++k) {
    double num = 0, den = 0;
    for (int i = k; i < n; ++i) {
      num += f[i] * b[i - 1];
      den += f[i] * f[i] + b[i - 1] * b[i - 1];
    }
    double r = 0;
    if (den > 1e-12 * 2 * energy && den > 0) r = -2 * num / den;  // else: nothing left to model
    std::vector<double> next(static_cast<size_t>(k));
    for (int i = 1; i < k; ++i)
      next[static_cast<size_t>(i - 1)] =
          a[static_cast<size_t>(i - 1)] + r * a[static_cast<size_t>(k - i - 1)];
    next[static_cast<size_t>(k - 1)] = r;
    a = std::move(next);
    for (int i = n - 1; i >= k; --i) {  // downwards, so b[i-1] is still the previous stage's
      const double fi = f[i];
      f[i] = fi + r * b[i - 1];
      b[i] = b[i - 1] + r * fi;
    }
    e *= (1 - r * r);
    out.reflection_coeffs.push_back(r);
    out.error_power.push_back(e);
  }
  out.coefficients = a;
  return out;
}

double predict_next(const std::vector<double>& a, const double* history, int size) {
  double s = 0;
  const int p = static_cast<int>(a.size());
  for (int k = 1; k <= p && k <= size; ++k) s -= a[static_cast<size_t>(k - 1)] * history[size - k];
  return s;
}

}  // namespace sg::predictor
