// Driver of the second-order derivative benchmarks. Without arguments (or with --benchmark_*
// flags): Google Benchmark over every algorithm x robot (double). With `--run <robot> <algo> <n>`:
// calls that algorithm n times and exits (second_order_counts.sh: instructions per call).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#define ARBOR_ROBOT(name, Struct) bool arbor_so_run_##name(const char*, long);
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT

int main(int argc, char** argv) {
  if (argc == 5 && std::strcmp(argv[1], "--run") == 0) {
    const std::string robot = argv[2];
    const long n = std::atol(argv[4]);
    bool ok = false;
#define ARBOR_ROBOT(name, Struct) \
  if (robot == #name)             \
    ok = arbor_so_run_##name(argv[3], n);
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT
    if (!ok)
      std::fprintf(stderr, "unknown robot or algorithm\n");
    return ok ? 0 : 1;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
