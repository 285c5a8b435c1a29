// Benchmarks of the contracted second-order derivatives for one robot: the Hessians of
// lambda' ID (rnea_second_order_derivatives) and lambda' FD (aba_second_order_derivatives), the
// four n x n x n tensors of ID (rnea_second_order_tensors), the first-order sweeps for scale, and,
// when requested (the Kinova Gen3), the AD layer's Hessians of the same functions: nested duals
// (H^c, ad::contracted_hessian<AutoDiff>) and duals through the first-order routines (H^a,
// <Analytical>). Google Benchmark for time; run_loop for callgrind.
#pragma once

#include <benchmark/benchmark.h>

#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <arbor/derivatives/derivatives.hpp>
#include <arbor/derivatives/rnea_second_order_tensors.hpp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string_view>

namespace arbor::bench_so {

/// Fixed pseudo-random inputs in [-1, 1] (tau in [-5, 5]).
template <class R>
struct Inputs {
  VecN<double, R::nv> q, v, a, tau, lambda;
  Inputs() {
    std::mt19937 gen(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < R::nv; ++i) {
      q[i] = u(gen);
      v[i] = u(gen);
      a[i] = u(gen);
      tau[i] = 5 * u(gen);
      lambda[i] = u(gen);
    }
  }
};

/// One algorithm on robot R: its workspace and one call.
template <class R, class Algo>
struct Case;

struct IdHessian {
  static constexpr const char* name = "id_hessian";
};
struct FdHessian {
  static constexpr const char* name = "fd_hessian";
};
struct IdTensors {
  static constexpr const char* name = "id_tensors";
};
struct IdJacobian {
  static constexpr const char* name = "rnea_derivatives";
};
struct FdJacobian {
  static constexpr const char* name = "aba_derivatives";
};
template <class Tag>
struct IdHessianAd {
  static constexpr const char* name =
      std::is_same_v<Tag, ad::AutoDiff> ? "id_hessian_Hc" : "id_hessian_Ha";
};
template <class Tag>
struct FdHessianAd {
  static constexpr const char* name =
      std::is_same_v<Tag, ad::AutoDiff> ? "fd_hessian_Hc" : "fd_hessian_Ha";
};

template <class R>
struct Case<R, IdHessian> {
  Data<R> d;
  SecondOrderData<R> s;
  const void* operator()(const Inputs<R>& in) {
    rnea_second_order_derivatives<R>(d, s, in.q, in.v, in.a, in.lambda);
    return s.hessian.data();
  }
};
template <class R>
struct Case<R, FdHessian> {
  Data<R> d;
  DerivativeData<R> dd;
  SecondOrderData<R> s;
  const void* operator()(const Inputs<R>& in) {
    aba_second_order_derivatives<R>(d, dd, s, in.q, in.v, in.tau, in.lambda);
    return s.hessian.data();
  }
};
template <class R>
struct Case<R, IdTensors> {
  Data<R> d;
  SecondOrderData<R> s;
  SecondOrderTensors<R> t;
  const void* operator()(const Inputs<R>& in) {
    rnea_second_order_tensors<R>(d, s, t, in.q, in.v, in.a);
    return t.d2tau_dqdq[0].data();
  }
};
template <class R>
struct Case<R, IdJacobian> {
  Data<R> d;
  DerivativeData<R> dd;
  const void* operator()(const Inputs<R>& in) {
    rnea_derivatives<R>(d, dd, in.q, in.v, in.a);
    return dd.dtau_dq.data();
  }
};
template <class R>
struct Case<R, FdJacobian> {
  Data<R> d;
  DerivativeData<R> dd;
  const void* operator()(const Inputs<R>& in) {
    aba_derivatives<R>(d, dd, in.q, in.v, in.tau);
    return dd.ddq_dq.data();
  }
};
template <class R, class F, class Tag>
struct AdCase {
  ad::HessianWorkspace<F, Tag> ws;
  VecN<double, F::nin> x;
  VecN<double, F::nout> y;
  Eigen::Matrix<double, F::nin, F::nin> H;
  const void* run(const Inputs<R>& in, const VecN<double, R::nv>& third) {
    x << in.q, in.v, third;
    ad::contracted_hessian<Tag>(ad::bind<F>(ws), x, in.lambda, y, H);
    return H.data();
  }
};
template <class R, class Tag>
struct Case<R, IdHessianAd<Tag>> : AdCase<R, ad::InverseDynamics<R>, Tag> {
  const void* operator()(const Inputs<R>& in) { return this->run(in, in.a); }
};
template <class R, class Tag>
struct Case<R, FdHessianAd<Tag>> : AdCase<R, ad::ForwardDynamics<R>, Tag> {
  const void* operator()(const Inputs<R>& in) { return this->run(in, in.tau); }
};

template <class R, class Algo>
void bm(benchmark::State& st) {
  auto c = std::make_unique<Case<R, Algo>>();
  auto in = std::make_unique<Inputs<R>>();
  for (auto _ : st) {
    benchmark::DoNotOptimize(in->q.data());
    benchmark::DoNotOptimize((*c)(*in));
    benchmark::ClobberMemory();
  }
}

/// Calls Algo n times (callgrind runner).
template <class R, class Algo>
void loop(long n) {
  auto c = std::make_unique<Case<R, Algo>>();
  auto in = std::make_unique<Inputs<R>>();
  for (long k = 0; k < n; ++k) {
    benchmark::DoNotOptimize(in->q.data());
    benchmark::DoNotOptimize((*c)(*in));
    benchmark::ClobberMemory();
  }
}

template <class R, class... Algos>
struct AlgoList {
  static void register_all(const char* robot) {
    char name[128];
    ((std::snprintf(name, sizeof name, "%s/%s", robot, Algos::name),
      benchmark::RegisterBenchmark(name, &bm<R, Algos>)),
     ...);
  }
  static bool run(const char* algo, long n) {
    bool found = false;
    ((std::strcmp(algo, Algos::name) == 0 ? (found = true, loop<R, Algos>(n), 0) : 0), ...);
    return found;
  }
};

/// The algorithms of robot R: the AD Hessians only when WithAd.
template <class R, bool WithAd>
using Algorithms = std::conditional_t<
    WithAd,
    AlgoList<R, IdHessian, FdHessian, IdTensors, IdJacobian, FdJacobian, IdHessianAd<ad::AutoDiff>,
             IdHessianAd<ad::Analytical>, FdHessianAd<ad::AutoDiff>, FdHessianAd<ad::Analytical>>,
    AlgoList<R, IdHessian, FdHessian, IdTensors, IdJacobian, FdJacobian>>;

}  // namespace arbor::bench_so

/// Registers robot T under `name` and defines its callgrind runner arbor_so_run_<name>.
#define ARBOR_SO_BENCH_ROBOT(T, name, with_ad)                                \
  namespace {                                                                 \
  [[maybe_unused]] const bool registered_##name =                             \
      (::arbor::bench_so::Algorithms<T, with_ad>::register_all(#name), true); \
  }                                                                           \
  bool arbor_so_run_##name(const char* algo, long n) {                        \
    return ::arbor::bench_so::Algorithms<T, with_ad>::run(algo, n);           \
  }
