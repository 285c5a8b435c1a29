// Timings of the paper's Fig. 1 (J^a and J^c of FD and ID) and Table 2 (Hessians of
// lambda^T FD and lambda^T ID, H^c and H^a) with Google Benchmark. Benchmark names:
// "<quantity>/<robot>", quantity in J_FD_a, J_FD_c, J_ID_a, J_ID_c, H_FD_c, H_FD_a, H_ID_c,
// H_ID_a, and J_FD_g, J_ID_g, H_FD_g, H_ID_g for the Generated provider (gen/ad).
// bench/ad/report.sh turns them into tables and the PNG.
#pragma once

#include <benchmark/benchmark.h>

#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <memory>
#include <string>

namespace arbor::bench_ad {

template <int N>
VecN<double, N> inputs(double offset) {
  VecN<double, N> x;
  for (int i = 0; i < N; ++i)
    x[i] = 0.3 + offset + 0.37 * i - 0.05 * (i % 5) * i;
  return x;
}

template <class F, class Tag>
void bm_jacobian(benchmark::State& st) {
  const auto x = inputs<F::nin>(0.0);
  VecN<double, F::nout> y;
  static Eigen::Matrix<double, F::nout, F::nin> J;
  auto ws = std::make_unique<ad::JacobianWorkspace<F, Tag>>();
  const auto f = ad::bind<F>(*ws);
  for (auto _ : st) {
    f.template value_and_jacobian<Tag>(x, y, J);
    benchmark::DoNotOptimize(J.data());
    benchmark::ClobberMemory();
  }
}

template <class F, class Tag>
void bm_hessian(benchmark::State& st) {
  const auto x = inputs<F::nin>(0.0);
  const auto lambda = inputs<F::nout>(0.1);
  VecN<double, F::nout> y;
  static Eigen::Matrix<double, F::nin, F::nin> H;
  auto ws = std::make_unique<ad::HessianWorkspace<F, Tag>>();
  const auto f = ad::bind<F>(*ws);
  for (auto _ : st) {
    ad::contracted_hessian<Tag>(f, x, lambda, y, H);
    benchmark::DoNotOptimize(H.data());
    benchmark::ClobberMemory();
  }
}

/// Registers J_FD_a, J_FD_c, J_ID_a, J_ID_c of robot R (and the Hessians if requested: H^c, H^a
/// and H^s, the analytical second-order routines).
template <class R, bool Hessians>
void register_robot(const std::string& name) {
  using FD = ad::ForwardDynamics<R>;
  using ID = ad::InverseDynamics<R>;
  benchmark::RegisterBenchmark(("J_FD_a/" + name).c_str(), bm_jacobian<FD, ad::Analytical>);
  benchmark::RegisterBenchmark(("J_FD_c/" + name).c_str(), bm_jacobian<FD, ad::AutoDiff>);
  benchmark::RegisterBenchmark(("J_ID_a/" + name).c_str(), bm_jacobian<ID, ad::Analytical>);
  benchmark::RegisterBenchmark(("J_ID_c/" + name).c_str(), bm_jacobian<ID, ad::AutoDiff>);
  if constexpr (Hessians) {
    benchmark::RegisterBenchmark(("H_FD_c/" + name).c_str(), bm_hessian<FD, ad::AutoDiff>);
    benchmark::RegisterBenchmark(("H_FD_a/" + name).c_str(), bm_hessian<FD, ad::Analytical>);
    benchmark::RegisterBenchmark(("H_ID_c/" + name).c_str(), bm_hessian<ID, ad::AutoDiff>);
    benchmark::RegisterBenchmark(("H_ID_a/" + name).c_str(), bm_hessian<ID, ad::Analytical>);
    benchmark::RegisterBenchmark(("H_FD_s/" + name).c_str(), bm_hessian<FD, ad::SecondOrder>);
    benchmark::RegisterBenchmark(("H_ID_s/" + name).c_str(), bm_hessian<ID, ad::SecondOrder>);
  }
}

/// Registers J_FD_g, J_ID_g (and H_FD_g, H_ID_g if generated) of robot R: the Generated
/// provider, whose header the calling unit includes.
template <class R>
void register_generated(const std::string& name) {
  using FD = ad::ForwardDynamics<R>;
  using ID = ad::InverseDynamics<R>;
  benchmark::RegisterBenchmark(("J_FD_g/" + name).c_str(), bm_jacobian<FD, ad::Generated>);
  benchmark::RegisterBenchmark(("J_ID_g/" + name).c_str(), bm_jacobian<ID, ad::Generated>);
  if constexpr (ad::GeneratedHessian<FD>::available) {
    benchmark::RegisterBenchmark(("H_FD_g/" + name).c_str(), bm_hessian<FD, ad::Generated>);
    benchmark::RegisterBenchmark(("H_ID_g/" + name).c_str(), bm_hessian<ID, ad::Generated>);
  }
}

#define ARBOR_ROBOT(name, Struct) \
  void register_##name();         \
  void register_generated_##name();
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT

}  // namespace arbor::bench_ad
