// The contour example's tracking residual (examples/contour/task.hpp, TrackResidualT) as an
// ad::UserFunction, for bench/ad/fn_counts.cpp: inputs [pose (12), s, sd], parameters the
// reference [p0 (3), R0 (9), c], so that arbor_add_function_ad generates its Jacobian with the
// reference as run-time values.
#pragma once

#include <task.hpp>

namespace arbor::bench_ad {

/// [sd - sd_ref(s), e_p (3), e_R (3), 1 - s, sd] of x = [pose (12), s, sd]; p = [p0, R0, c].
struct TrackFunction {
  static constexpr int nin = 14, nout = 9, nparam = 13;
  template <class S>
  static void eval(const S* x, const S* p, S* y) {
    contour::ReferenceT<S> ref;
    for (int i = 0; i < 3; ++i)
      ref.p0[std::size_t(i)] = p[i];
    for (int i = 0; i < 9; ++i)
      ref.R0[std::size_t(i)] = p[3 + i];
    ref.c = p[12];
    VecN<S, 12> pose;
    for (int i = 0; i < 12; ++i)
      pose[i] = x[i];
    const VecN<S, 2> ssd(x[12], x[13]);
    const VecN<S, 9> r = contour::TrackResidualT<S>{ref}(pose, ssd);
    for (int i = 0; i < 9; ++i)
      y[i] = r[i];
  }
};

/// The parameters of TrackFunction for reference r.
inline std::array<double, 13> track_parameters(const contour::Reference& r) {
  std::array<double, 13> p{};
  for (int i = 0; i < 3; ++i)
    p[std::size_t(i)] = r.p0[std::size_t(i)];
  for (int i = 0; i < 9; ++i)
    p[std::size_t(3 + i)] = r.R0[std::size_t(i)];
  p[12] = r.c;
  return p;
}

}  // namespace arbor::bench_ad
