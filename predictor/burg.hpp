#pragma once

#include <array>
#include <deque>
#include <vector>

namespace sg::predictor {

/// Burg's method in one consistent form (Octave's `arburg`, Marple; see shared reference
/// burg.md), with the sign error of the paper's eq. 30-32 corrected: starting from
/// e_f = e_b = x,
///   r_k = -2 sum_n e_f(n) e_b(n-1) / sum_n (e_f(n)^2 + e_b(n-1)^2)          (eq. 30)
///   e_f'(n) = e_f(n) + r_k e_b(n-1),   e_b'(n) = e_b(n-1) + r_k e_f(n)     (eq. 31, 32 corrected)
///   a_k(i) = a_{k-1}(i) + r_k a_{k-1}(k-i),  a_k(k) = r_k                 (eq. 29)
/// and the prediction of eq. 27, S_n = -sum_k a_k S_{n-k}.
struct BurgResult {
  std::vector<double> reflection_coeffs;  ///< r_1 .. r_p
  std::vector<double> coefficients;       ///< a_1 .. a_p (arburg returns [1, a_1 .. a_p])
  std::vector<double> error_power;  ///< E_0 .. E_p; E_k = E_{k-1} (1 - r_k^2), E_0 = sum x^2 / N
};

/// Burg's estimate of order `order` from x[0..n). Double precision; the sums are computed directly
/// at each stage. When the remaining error energy falls below 1e-12 of the signal's (a constant or
/// exactly predictable signal), the remaining reflection coefficients are 0 instead of 0/0.
/// Needs n > order.
BurgResult burg(const double* x, int n, int order);

/// burg() of three signals (the x, y and z windows) in one pass: the same operations on the three
/// at once, in the lanes of one AVX2 register, so each result is bit for bit burg()'s (a test)
/// for about the time of one (issue 19). Needs n > order.
std::array<BurgResult, 3> burg3(const std::array<const double*, 3>& x, int n, int order);

/// burg3 of three windows with their means taken off (x - mean, as the axis models centre them),
/// read from the windows themselves rather than from centred copies. Needs all three windows of
/// one size n > order.
std::array<BurgResult, 3> burg3_centred(const std::array<const std::deque<double>*, 3>& windows,
                                        const std::array<double, 3>& means, int order);

/// One-step prediction of eq. 27 from the last p values of `history` (oldest first):
/// -sum_k a_k history[size - k].
double predict_next(const std::vector<double>& coefficients, const double* history, int size);

}  // namespace sg::predictor
