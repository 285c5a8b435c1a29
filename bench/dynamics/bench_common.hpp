// Benchmark support: one call of each algorithm on fixed random inputs, for Google Benchmark
// (time) and for the callgrind runner (instructions per call).
#pragma once

#include <arbor/derivatives/derivatives.hpp>
#include <arbor/dynamics/dynamics.hpp>
#include <cstring>
#include <random>
#include <string>

namespace arbor::bench {

enum class Algo {
  fk,
  rnea,
  gravity,
  nle,
  crba,
  aba,
  minverse,
  jacobian,
  cholesky,
  rnea_derivatives,
  aba_derivatives
};
// The same driver builds the dynamics benchmarks (bench/dynamics) and, with
// ARBOR_BENCH_DERIVATIVES, the derivative benchmarks (bench/derivatives).
#ifdef ARBOR_BENCH_DERIVATIVES
inline constexpr Algo kAlgos[] = {Algo::rnea_derivatives, Algo::aba_derivatives};
#else
inline constexpr Algo kAlgos[] = {Algo::fk,       Algo::rnea,     Algo::gravity,
                                  Algo::nle,      Algo::crba,     Algo::aba,
                                  Algo::minverse, Algo::jacobian, Algo::cholesky};
#endif
inline const char* algo_name(Algo a) {
  switch (a) {
    case Algo::fk:
      return "fk";
    case Algo::rnea:
      return "rnea";
    case Algo::gravity:
      return "gravity";
    case Algo::nle:
      return "nle";
    case Algo::crba:
      return "crba";
    case Algo::aba:
      return "aba";
    case Algo::minverse:
      return "minverse";
    case Algo::jacobian:
      return "jacobian";
    case Algo::cholesky:
      return "cholesky";
    case Algo::rnea_derivatives:
      return "rnea_derivatives";
    case Algo::aba_derivatives:
      return "aba_derivatives";
  }
  return "?";
}

/// Fixed pseudo-random inputs.
template <class R, class S>
struct Inputs {
  VecN<S, R::nv> q, v, a, tau;
  Mat6N<S, R::nv> J;
  DerivativeData<R, S> deriv;  ///< workspace of the derivative algorithms
  Inputs() {
    std::mt19937 g(1234);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < R::nv; ++i) {
      q[i] = S(u(g));
      v[i] = S(u(g));
      a[i] = S(u(g));
      tau[i] = S(u(g));
    }
    J.setZero();
  }
};

/// One call of algorithm A; returns a pointer into the outputs (to keep them alive).
template <class R, class S, Algo A>
ARBOR_INLINE const void* call(Data<R, S>& d, Inputs<R, S>& in) {
  if constexpr (A == Algo::fk) {
    forward_kinematics<R>(d, in.q);
    return &d.oMi;
  } else if constexpr (A == Algo::rnea) {
    return &rnea<R>(d, in.q, in.v, in.a);
  } else if constexpr (A == Algo::gravity) {
    return &gravity<R>(d, in.q);
  } else if constexpr (A == Algo::nle) {
    return &nle<R>(d, in.q, in.v);
  } else if constexpr (A == Algo::crba) {
    return &crba<R>(d, in.q);
  } else if constexpr (A == Algo::aba) {
    return &aba<R>(d, in.q, in.v, in.tau);
  } else if constexpr (A == Algo::minverse) {
    return &minverse<R>(d, in.q);
  } else if constexpr (A == Algo::jacobian) {
    compute_frame_jacobian<R>(d, in.q, R::nf - 1, ReferenceFrame::local_world_aligned, in.J);
    return &in.J;
  } else if constexpr (A == Algo::rnea_derivatives) {
    rnea_derivatives<R>(d, in.deriv, in.q, in.v, in.a);
    return &in.deriv.dtau_dq;
  } else if constexpr (A == Algo::aba_derivatives) {
    aba_derivatives<R>(d, in.deriv, in.q, in.v, in.tau);
    return &in.deriv.ddq_dq;
  } else {
    // M from crba, then a Cholesky solve M x = tau (the dense alternative to aba/minverse)
    crba<R>(d, in.q);
    cholesky_factor<R>(d);
    in.a = cholesky_solve<R>(d, in.tau);
    return &in.a;
  }
}

}  // namespace arbor::bench
