// arbor: the sines and cosines of all revolute joints at once (double). detail::sincos_double
// (core/math.hpp) computed lane by lane in one straight loop without branches, so that the
// compiler runs it across SIMD lanes (4 joints per instruction with AVX2): the same operations in
// the same order, so bit for bit the same results as sincos_double for every argument. The
// arguments sincos_double treats apart (|x| > 1e5, non-finite, |x| < 2^-26 where -0.0 keeps its
// sign) are found by one test over all lanes on the bits of |x| and redone by sincos_double.
// Kinova Gen3, seven joints: about 7 x 71 instructions one by one, about 200 in two AVX2 passes.
#pragma once

#include <bit>
#include <cstdint>

#include "arbor/core/config.hpp"
#include "arbor/core/math.hpp"

namespace arbor::detail {

/// The lane count the batch is padded to: a whole number of SIMD registers of doubles where the
/// target has them (padding costs work where it does not).
#if defined(__AVX__)
inline constexpr int kSincosLanes = 4;
#elif defined(__SSE2__) || defined(__ARM_NEON) || defined(__aarch64__)
inline constexpr int kSincosLanes = 2;
#else
inline constexpr int kSincosLanes = 1;
#endif

/// s[j], c[j] = sin x[j], cos x[j] for j < N, each bit for bit sincos_double(x[j]).
template <int N>
ARBOR_INLINE void sincos_double_batch(const double* x, double* s, double* c) {
  constexpr double two_over_pi = 0x1.45f306dc9c883p-1;
  constexpr double pi2_1 = 0x1.921fb54400000p+0;
  constexpr double pi2_2 = 0x1.0b4611a600000p-34;
  constexpr double pi2_3 = 0x1.3198a2e037073p-69;
  constexpr double s3 = -inv_factorial(3), s5 = inv_factorial(5), s7 = -inv_factorial(7),
                   s9 = inv_factorial(9), s11 = -inv_factorial(11), s13 = inv_factorial(13),
                   s15 = -inv_factorial(15);
  constexpr double c4 = inv_factorial(4), c6 = -inv_factorial(6), c8 = inv_factorial(8),
                   c10 = -inv_factorial(10), c12 = inv_factorial(12), c14 = -inv_factorial(14),
                   c16 = inv_factorial(16);
  for (int j = 0; j < N; ++j) {  // sincos_double's general path, its quadrant switch as selects
    const double xj = x[j];
    const int k = static_cast<int>(xj * two_over_pi + (xj < 0 ? -0.5 : 0.5));
    const double kd = k;
    const double a = xj - kd * pi2_1, b = kd * pi2_2;
    const double d = a - b, bv = d - a;
    const double e = ((a - (d - bv)) - (b + bv)) - kd * pi2_3;
    const double rh = d + e, rl = e - (rh - d);
    const double z = rh * rh;
    const double ps = s3 + z * (s5 + z * (s7 + z * (s9 + z * (s11 + z * (s13 + z * s15)))));
    const double pc = c4 + z * (c6 + z * (c8 + z * (c10 + z * (c12 + z * (c14 + z * c16)))));
    const double hz = 0.5 * z;
    const double sr = rh + (rh * (z * ps) + rl * (1.0 - hz));
    const double w = 1.0 - hz;
    const double cr = w + (((1.0 - w) - hz) + ((z * z) * pc - rh * rl));
    const double s0 = (k & 1) ? cr : sr;
    const double c0 = (k & 1) ? sr : cr;
    s[j] = (k & 2) ? -s0 : s0;
    c[j] = ((k + 1) & 2) ? -c0 : c0;
  }
  // |x| outside [2^-26, 1e5] or NaN: the integer difference of the bits of |x| and of 2^-26 is
  // negative or above that of 1e5 (NaN and infinities have larger bits than any finite value)
  constexpr std::int64_t lo = std::bit_cast<std::int64_t>(0x1p-26);
  constexpr std::int64_t range = std::bit_cast<std::int64_t>(1e5) - lo;
  std::int64_t apart = 0;
  for (int j = 0; j < N; ++j) {
    const std::int64_t t = (std::bit_cast<std::int64_t>(x[j]) & INT64_MAX) - lo;
    apart |= std::int64_t(t > range) | std::int64_t(t < 0);
  }
  if (apart) [[unlikely]] {
    for (int j = 0; j < N; ++j) {
      const double xj = x[j];
      if (!(xj <= 1e5 && xj >= -1e5) || (xj < 0x1p-26 && xj > -0x1p-26))
        sincos_double(xj, s[j], c[j]);
    }
  }
}

}  // namespace arbor::detail
