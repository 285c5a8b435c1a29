// arbor: scalar customisation points. Every algorithm calls arbor::sin/cos/sqrt, never std::
// directly, so that AD and operation-counting scalar types plug in by overloading these names in
// their own namespace (found by argument-dependent lookup) or in namespace arbor.
#pragma once

#include <cmath>
#include <type_traits>

#include "arbor/core/config.hpp"

namespace arbor {

namespace math_detail {
using std::cos;
using std::sin;
using std::sqrt;
template <class T>
inline auto adl_sin(const T& x) -> decltype(sin(x)) {
  return sin(x);
}
template <class T>
inline auto adl_cos(const T& x) -> decltype(cos(x)) {
  return cos(x);
}
template <class T>
inline auto adl_sqrt(const T& x) -> decltype(sqrt(x)) {
  return sqrt(x);
}
}  // namespace math_detail

namespace detail {

/// 1 / n! correctly rounded (n! is exact in double up to 18!).
constexpr double inv_factorial(int n) {
  double f = 1.0;
  for (int k = 2; k <= n; ++k)
    f *= k;
  return 1.0 / f;
}

/// sin and cos of a double |x| <= 1e5 without a library call (libm's sincos costs ~110
/// instructions on x86-64 glibc and a few hundred in newlib on the Cortex-M7; this ~60, inline):
/// x = k pi/2 + r, |r| <= pi/4 (+ rounding), by Cody-Waite reduction with pi/2 split into two
/// 33-bit parts and a 53-bit tail (k pi2_1 and k pi2_2 are exact for |k| < 2^20, x - k pi2_1
/// is exact by Sterbenz' lemma), r kept as a sum of two doubles; then Taylor polynomials in z = r^2
/// to degree 15 (sin) and 16 (cos), whose truncation errors at r = pi/4 are 5e-17 and 2e-18 of the
/// result (below half an ulp); cos adds its leading 1 - z/2 with the rounding error of that
/// subtraction recovered. The quadrant k mod 4 permutes and negates. Measured against glibc
/// (tests/core/math_test.cpp, 1.2 M arguments and the doubles next to multiples of pi/2): within
/// 1 ulp of sin and cos; -0.0 keeps its sign. Beyond |x| <= 1e5, or for non-finite x: std::sin
/// and std::cos.
/// sincos_double's general path for 2^-26 <= |x| <= 1e5, without branches (the quadrant's
/// permutation and signs as selects), so that a loop over it runs across SIMD lanes
/// (core/sincos_batch.hpp).
ARBOR_INLINE void sincos_reduced(double x, double& s, double& c) {
  constexpr double two_over_pi = 0x1.45f306dc9c883p-1;
  constexpr double pi2_1 = 0x1.921fb54400000p+0;   // pi/2, first 33 bits
  constexpr double pi2_2 = 0x1.0b4611a600000p-34;  // next 33 bits
  constexpr double pi2_3 = 0x1.3198a2e037073p-69;  // the rest, rounded
  // nearest integer without a library call or the rounding mode (robust to -ffast-math): an
  // error of one near a half only leaves |r| slightly above pi/4, where the series still hold
  const int k = static_cast<int>(x * two_over_pi + (x < 0 ? -0.5 : 0.5));
  const double kd = k;
  // r = rh + rl in two doubles: a - b with its rounding error (TwoSum: a and b cancel near the
  // multiples of pi/2), minus the tail's product
  const double a = x - kd * pi2_1, b = kd * pi2_2;
  const double d = a - b, bv = d - a;
  const double e = ((a - (d - bv)) - (b + bv)) - kd * pi2_3;
  const double rh = d + e, rl = e - (rh - d);
  const double z = rh * rh;
  constexpr double s3 = -inv_factorial(3), s5 = inv_factorial(5), s7 = -inv_factorial(7),
                   s9 = inv_factorial(9), s11 = -inv_factorial(11), s13 = inv_factorial(13),
                   s15 = -inv_factorial(15);
  constexpr double c4 = inv_factorial(4), c6 = -inv_factorial(6), c8 = inv_factorial(8),
                   c10 = -inv_factorial(10), c12 = inv_factorial(12), c14 = -inv_factorial(14),
                   c16 = inv_factorial(16);
  const double ps = s3 + z * (s5 + z * (s7 + z * (s9 + z * (s11 + z * (s13 + z * s15)))));
  const double pc = c4 + z * (c6 + z * (c8 + z * (c10 + z * (c12 + z * (c14 + z * c16)))));
  const double hz = 0.5 * z;
  // sin(rh + rl) = sin rh + rl cos rh, cos(rh + rl) = cos rh - rl sin rh, to first order in rl
  const double sr = rh + (rh * (z * ps) + rl * (1.0 - hz));
  const double w = 1.0 - hz;  // rounded; its rounding error is added back
  const double cr = w + (((1.0 - w) - hz) + ((z * z) * pc - rh * rl));
  // quadrant k mod 4: (sr, cr), (cr, -sr), (-sr, -cr), (-cr, sr)
  const double s0 = (k & 1) ? cr : sr;
  const double c0 = (k & 1) ? sr : cr;
  s = (k & 2) ? -s0 : s0;
  c = ((k + 1) & 2) ? -c0 : c0;
}

inline void sincos_double(double x, double& s, double& c) {
  if (!(x <= 1e5 && x >= -1e5)) {  // also NaN
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  if (x < 0x1p-26 && x > -0x1p-26) {  // sin x = x and cos x = 1 to rounding (keeps -0.0)
    s = x;
    c = 1.0;
    return;
  }
  sincos_reduced(x, s, c);
}

}  // namespace detail

/// Sine; double uses detail::sincos_double (the compiler shares its work with a cos of the same
/// argument), float std::sin, others the overload found by ADL.
template <class T>
inline T sin(const T& x) {
  if constexpr (std::is_same_v<T, double>) {
    double s, c;
    detail::sincos_double(x, s, c);
    return s;
  } else {
    return T(math_detail::adl_sin(x));
  }
}
/// Cosine; double uses detail::sincos_double, float std::cos, others the overload found by ADL.
template <class T>
inline T cos(const T& x) {
  if constexpr (std::is_same_v<T, double>) {
    double s, c;
    detail::sincos_double(x, s, c);
    return c;
  } else {
    return T(math_detail::adl_cos(x));
  }
}
/// Square root; built-in floating types use std::sqrt, others the overload found by ADL.
template <class T>
inline T sqrt(const T& x) {
  return T(math_detail::adl_sqrt(x));
}

/// Sine and cosine of the same angle (one call site, so a scalar type may share work). A scalar
/// type that can compute both at once provides `arbor_sincos(x, s, c)`, found by ADL; double uses
/// detail::sincos_double (no library call), float std::sin and std::cos.
template <class T>
inline void sincos(const T& x, T& s, T& c) {
  if constexpr (std::is_same_v<T, double>) {
    detail::sincos_double(x, s, c);
  } else if constexpr (requires { arbor_sincos(x, s, c); }) {
    arbor_sincos(x, s, c);
  } else {
    s = arbor::sin(x);
    c = arbor::cos(x);
  }
}

/// True when x is known to be zero, so that work multiplied by it may be skipped. Numbers: x ==
/// 0. A tracing scalar (a code generator's) overloads `known_zero` in its namespace, found by
/// ADL, to answer from structure only (the constant zero), so that a skip never depends on the
/// value at the point it traces at.
template <class T>
constexpr bool known_zero(const T& x) {
  return x == T(0);
}

/// True when a and b are known to be equal, so that a value computed at one may be reused at the
/// other. Numbers: a == b (NaN never). A tracing scalar answers from structure (the same node).
template <class T>
constexpr bool known_equal(const T& a, const T& b) {
  return a == b;
}

/// max(x, 0). A tracing scalar overloads `positive_part` in its namespace (found by ADL) with an
/// operation of its own instead of a comparison of values.
template <class T>
constexpr T positive_part(const T& x) {
  return x > T(0) ? x : T(0);
}

/// 1 if x > 0, else 0 (positive_part's derivative). A tracing or SIMD scalar overloads
/// `unit_step` in its namespace, as positive_part.
template <class T>
constexpr T unit_step(const T& x) {
  return x > T(0) ? T(1) : T(0);
}

}  // namespace arbor
