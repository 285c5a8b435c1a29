// Google Benchmark registration of every algorithm for one robot, double and float.
#pragma once

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>

#include "bench_common.hpp"

namespace arbor::bench {

template <class R, class S, Algo A>
void bm(benchmark::State& st) {
  auto d = std::make_unique<Data<R, S>>();
  auto in = std::make_unique<Inputs<R, S>>();
  for (auto _ : st) {
    benchmark::DoNotOptimize(in->q.data());
    const void* out = call<R, S, A>(*d, *in);
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}

template <class R, class S>
void register_scalar(const char* robot, const char* scalar) {
  [&]<std::size_t... Is>(std::index_sequence<Is...>) {
    char name[128];
    ((std::snprintf(name, sizeof name, "%s/%s/%s", robot, algo_name(kAlgos[Is]), scalar),
      benchmark::RegisterBenchmark(name, &bm<R, S, kAlgos[Is]>)),
     ...);
  }
  (std::make_index_sequence<std::size(kAlgos)>{});
}

template <class R>
bool register_robot(const char* robot) {
  register_scalar<R, double>(robot, "double");
  register_scalar<R, float>(robot, "float");
  return true;
}

/// Callgrind runner entry: calls the algorithm `n` times; returns false for an unknown name.
template <class R, class S>
bool run_loop(const char* algo, long n) {
  auto d = std::make_unique<Data<R, S>>();
  auto in = std::make_unique<Inputs<R, S>>();
  bool found = false;
  [&]<std::size_t... Is>(std::index_sequence<Is...>) {
    ((std::strcmp(algo, algo_name(kAlgos[Is])) == 0
          ? (
                found = true,
                [&] {
                  for (long k = 0; k < n; ++k) {
                    benchmark::DoNotOptimize(in->q.data());
                    benchmark::DoNotOptimize(call<R, S, kAlgos[Is]>(*d, *in));
                    benchmark::ClobberMemory();
                  }
                }(),
                0)
          : 0),
     ...);
  }
  (std::make_index_sequence<std::size(kAlgos)>{});
  return found;
}

}  // namespace arbor::bench

/// Defines the registration of robot type T under `name` and its callgrind runner function.
#define ARBOR_BENCH_ROBOT(T, name)                                                             \
  namespace {                                                                                  \
  [[maybe_unused]] const bool registered_##name = ::arbor::bench::register_robot<T>(#name);    \
  }                                                                                            \
  bool arbor_run_##name(const char* algo, const char* scalar, long n) {                        \
    return std::string_view(scalar) == "float" ? ::arbor::bench::run_loop<T, float>(algo, n)   \
                                               : ::arbor::bench::run_loop<T, double>(algo, n); \
  }
