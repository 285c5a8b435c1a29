// Benchmark driver. Without arguments (or with --benchmark_* flags): Google Benchmark over every
// algorithm x robot x scalar. With `--run <robot> <algo> <double|float> <n>`: calls that
// algorithm n times and exits (used by bench/callgrind_counts.sh to count instructions per call).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

bool arbor_run_double_pendulum(const char*, const char*, long);
bool arbor_run_iiwa7(const char*, const char*, long);
bool arbor_run_kinova_gen3(const char*, const char*, long);
bool arbor_run_yumi_no_grippers(const char*, const char*, long);
bool arbor_run_atlas(const char*, const char*, long);

int main(int argc, char** argv) {
  if (argc == 6 && std::strcmp(argv[1], "--run") == 0) {
    const std::string robot = argv[2];
    const long n = std::atol(argv[5]);
    bool ok = false;
    if (robot == "double_pendulum")
      ok = arbor_run_double_pendulum(argv[3], argv[4], n);
    if (robot == "iiwa7")
      ok = arbor_run_iiwa7(argv[3], argv[4], n);
    if (robot == "kinova_gen3")
      ok = arbor_run_kinova_gen3(argv[3], argv[4], n);
    if (robot == "yumi_no_grippers")
      ok = arbor_run_yumi_no_grippers(argv[3], argv[4], n);
    if (robot == "atlas")
      ok = arbor_run_atlas(argv[3], argv[4], n);
    if (!ok)
      std::fprintf(stderr, "unknown robot or algorithm\n");
    return ok ? 0 : 1;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
