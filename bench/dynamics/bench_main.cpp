// Benchmark driver. Without arguments (or with --benchmark_* flags): Google Benchmark over every
// algorithm x robot x scalar. With `--run <robot> <algo> <double|float> <n>`: calls that
// algorithm n times and exits (used by bench/callgrind_counts.sh to count instructions per call).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

// One runner per benchmark robot (examples/robots: the one robot list).
#define ARBOR_ROBOT(name, Struct) bool arbor_run_##name(const char*, const char*, long);
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT

int main(int argc, char** argv) {
  if (argc == 6 && std::strcmp(argv[1], "--run") == 0) {
    const std::string robot = argv[2];
    const long n = std::atol(argv[5]);
    bool ok = false;
#define ARBOR_ROBOT(name, Struct) \
  if (robot == #name)             \
    ok = arbor_run_##name(argv[3], argv[4], n);
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
