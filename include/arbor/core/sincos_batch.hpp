// arbor: the sines and cosines of N doubles at once (a robot's revolute joints, the lanes of a
// Pack<double, L> of core/pack.hpp). sincos_double's general path, detail::sincos_reduced
// (core/math.hpp, branch-free), called lane by lane in one straight loop, so that the compiler
// runs it across SIMD lanes (4 joints per instruction with AVX2): the results of sincos_double
// for every argument, bit for bit where the compiler does not contract a * b + c into fused
// multiply-adds (-ffp-contract=off), else within an ulp or so (it may contract the lanes and a
// scalar call differently). The arguments sincos_double treats
// apart (|x| > 1e5, non-finite, |x| < 2^-26 where -0.0 keeps its sign) are found by one test over
// all lanes on the bits of |x| and redone by sincos_double (their lanes' first results, garbage,
// are overwritten). Kinova Gen3, seven joints: about 7 x 71 instructions one by one, about 200 in
// two AVX2 passes.
#pragma once

#include <bit>
#include <cstdint>

#include "arbor/core/config.hpp"
#include "arbor/core/math.hpp"

namespace arbor::detail {

/// The lane count the batch is padded to: one SIMD register of doubles where the target has one
/// (simd_bytes, core/config.hpp), else 1 (padding costs work where there is no SIMD).
inline constexpr int kSincosLanes = simd_bytes >= 16 ? simd_bytes / 8 : 1;

/// s[j], c[j] = sin x[j], cos x[j] for j < N, each bit for bit sincos_double(x[j]).
template <int N>
ARBOR_INLINE void sincos_double_batch(const double* x, double* s, double* c) {
  for (int j = 0; j < N; ++j)  // sincos_double's general path, lane by lane
    sincos_reduced(x[j], s[j], c[j]);
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
