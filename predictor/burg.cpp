#include "predictor/burg.hpp"

#include <cstdint>
#include <stdexcept>
#include <type_traits>

namespace sg::predictor {
namespace {

/// Four doubles in one register (AVX2): the x, y and z axes and a spare lane of zeros.
using Lanes = double __attribute__((vector_size(32)));

/// The two sums of eq. 30 for the next stage: numerator sum e_f(n) e_b(n-1) and denominator
/// sum e_f(n)^2 + e_b(n-1)^2 (without eq. 30's factor -2). V: one axis (double) or three (Lanes),
/// the same operations in the same order, so each lane is bit for bit the one-axis result.
template <class V>
struct StageSums {
  V num{};
  V den{};
};

/// Stage 1's sums of eq. 30 over n = 1 .. N-1, with e_0^f = e_0^b = x (eq. 33, 34; burg.md's
/// "start").
template <class V>
[[gnu::always_inline]] inline StageSums<V> first_stage_sums(const V* f, const V* b, int n) {
  StageSums<V> s;
  for (int i = 1; i < n; ++i) {
    s.num += f[i] * b[i - 1];
    s.den += f[i] * f[i] + b[i - 1] * b[i - 1];
  }
  return s;
}

/// eq. 30: r_k = -2 num / den; 0 when den is below 1e-12 of twice the signal's energy: nothing
/// is left to model (burg.md, traps: a constant signal would give 0/0).
double reflection(double num, double den, double energy) {
  double r = 0;
  if (den > 1e-12 * 2 * energy && den > 0) r = -2 * num / den;  // else: nothing to model
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
template <class V>
[[gnu::always_inline]] inline StageSums<V> next_stage(V* f, V* b, int n, int k, const V& r) {
  StageSums<V> s;
  {
    const V fi = f[n - 1], bi = b[n - 2];  // the top: no f[i+1] yet
    f[n - 1] = fi + r * bi;
    b[n - 1] = bi + r * fi;
  }
  // Two partial sums each, so consecutive additions do not wait on each other.
  V num2{}, den2{};
  int i = n - 2;
  for (; i - 1 >= k; i -= 2) {
    const V f0 = f[i], b0 = b[i - 1], f1 = f[i - 1], b1 = b[i - 2];
    const V f0n = f0 + r * b0, b0n = b0 + r * f0;
    const V f1n = f1 + r * b1, b1n = b1 + r * f1;
    s.num += f[i + 1] * b0n;
    s.den += f[i + 1] * f[i + 1] + b0n * b0n;
    num2 += f0n * b1n;
    den2 += f0n * f0n + b1n * b1n;
    f[i] = f0n, b[i] = b0n, f[i - 1] = f1n, b[i - 1] = b1n;
  }
  for (; i >= k; --i) {
    const V fi = f[i], bi = b[i - 1];
    const V f_new = fi + r * bi, b_new = bi + r * fi;
    s.num += f[i + 1] * b_new;
    s.den += f[i + 1] * f[i + 1] + b_new * b_new;
    f[i] = f_new, b[i] = b_new;
  }
  s.num += num2;
  s.den += den2;
  return s;
}

double lane(double v, int) { return v; }
double lane(const Lanes& v, int l) { return v[l]; }

/// Burg's recursion on `axes` signals at once, held in f and b (e_0^f = e_0^b = x), their
/// energies given. V is double (one axis) or Lanes (up to three).
template <class V>
[[gnu::always_inline]] inline void burg_stages(V* f, V* b, int n, int order, const double* energy,
                                               int axes, BurgResult* out) {
  double e[3];
  for (int l = 0; l < axes; ++l) {
    e[l] = energy[l] / n;  // E_0
    out[l].reflection_coeffs.reserve(static_cast<size_t>(order));
    out[l].error_power.reserve(static_cast<size_t>(order) + 1);
    out[l].coefficients.reserve(static_cast<size_t>(order));
    out[l].error_power.push_back(e[l]);
  }
  StageSums<V> sums = first_stage_sums(f, b, n);
  for (int k = 1; k <= order; ++k) {
    V r{};
    for (int l = 0; l < axes; ++l) {
      const double rl = reflection(lane(sums.num, l), lane(sums.den, l), energy[l]);
      if constexpr (std::is_same_v<V, double>)
        r = rl;
      else
        r[l] = rl;
      update_coefficients(out[l].coefficients, rl, k);
      e[l] *= (1 - rl * rl);  // E_k = E_{k-1} (1 - r_k^2)
      out[l].reflection_coeffs.push_back(rl);
      out[l].error_power.push_back(e[l]);
    }
    if (k == order) break;  // the last stage's errors and sums would not be used
    sums = next_stage(f, b, n, k, r);
  }
}

/// The three axes' recursion, compiled for AVX2 (one instruction for the three) and for the
/// baseline; the loader picks the clone the CPU runs. The stages are inlined into each clone.
/// f and b: n Lanes each, aligned to 32 bytes, filled here with the three signals: `x(i, v)` sets
/// v to sample i of the three (a Lanes is not returned: without AVX the ABI would differ).
template <class Signals>
[[gnu::always_inline]] inline void burg_three(const Signals& x, Lanes* f, Lanes* b, int n,
                                              int order, BurgResult* out) {
  Lanes energy{};  // each lane summed in index order, as burg() sums its one signal
  for (int i = 0; i < n; ++i) {
    Lanes v;
    x(i, v);
    f[i] = b[i] = v;  // eq. 33, 34: e_0^f = e_0^b = x
    energy += v * v;
  }
  const double e[3] = {energy[0], energy[1], energy[2]};
  burg_stages(f, b, n, order, e, 3, out);
}

/// burg_three from three arrays.
__attribute__((target_clones("avx2", "default"))) void burg_three_arrays(
    const std::array<const double*, 3>& x, Lanes* f, Lanes* b, int n, int order, BurgResult* out) {
  burg_three(
      [&](int i, Lanes& v) {
        v = Lanes{x[0][i], x[1][i], x[2][i], 0};
      },
      f, b, n, order, out);
}

/// The same from three windows, each sample centred as it is read: w - m, as an axis model centres
/// its copy.
__attribute__((target_clones("avx2", "default"))) void burg_three_centred(
    const std::array<const std::deque<double>*, 3>& w, const std::array<double, 3>& m, Lanes* f,
    Lanes* b, int n, int order, BurgResult* out) {
  auto i0 = w[0]->begin(), i1 = w[1]->begin(), i2 = w[2]->begin();
  burg_three(
      [&](int, Lanes& v) {
        v = Lanes{*i0 - m[0], *i1 - m[1], *i2 - m[2], 0};
        ++i0, ++i1, ++i2;
      },
      f, b, n, order, out);
}

void check(int n, int order) {
  if (order < 1 || n <= order)
    throw std::invalid_argument("burg: needs more samples than the order");
}

}  // namespace

BurgResult burg(const double* x, int n, int order) {
  check(n, order);
  // Forward and backward errors, reused between calls (the predictor calls this every sample).
  thread_local std::vector<double> f_buffer, b_buffer;
  f_buffer.assign(x, x + n);  // eq. 33, 34: e_0^f = e_0^b = x
  b_buffer.assign(x, x + n);
  double energy = 0;
  for (int i = 0; i < n; ++i) energy += x[i] * x[i];
  BurgResult out;
  burg_stages(f_buffer.data(), b_buffer.data(), n, order, &energy, 1, &out);
  return out;
}

namespace {

/// burg3's f and b, n Lanes each: four doubles a sample in memory aligned to 32 bytes (a
/// std::vector of a vector type would lose the type's alignment: GCC drops attributes on template
/// arguments), kept from call to call.
Lanes* three_buffers(int n) {
  thread_local std::vector<double> memory;
  memory.resize(8 * static_cast<size_t>(n) + 4);
  const auto at = reinterpret_cast<uintptr_t>(memory.data());
  return reinterpret_cast<Lanes*>((at + 31) / 32 * 32);
}

}  // namespace

std::array<BurgResult, 3> burg3(const std::array<const double*, 3>& x, int n, int order) {
  check(n, order);
  Lanes* const f = three_buffers(n);
  std::array<BurgResult, 3> out;
  burg_three_arrays(x, f, f + n, n, order, out.data());
  return out;
}

std::array<BurgResult, 3> burg3_centred(const std::array<const std::deque<double>*, 3>& windows,
                                        const std::array<double, 3>& means, int order) {
  const size_t n = windows[0]->size();
  if (windows[1]->size() != n || windows[2]->size() != n)
    throw std::invalid_argument("burg3_centred: the three windows differ in length");
  check(static_cast<int>(n), order);
  Lanes* const f = three_buffers(static_cast<int>(n));
  std::array<BurgResult, 3> out;
  burg_three_centred(windows, means, f, f + n, static_cast<int>(n), order, out.data());
  return out;
}

double predict_next(const std::vector<double>& a, const double* history, int size) {
  double s = 0;
  const int p = static_cast<int>(a.size());
  for (int k = 1; k <= p && k <= size; ++k) s -= a[static_cast<size_t>(k - 1)] * history[size - k];
  return s;
}

}  // namespace sg::predictor
