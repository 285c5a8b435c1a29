// Driver of the AD timings (bench/ad/jacobian_bench.hpp).
#include "jacobian_bench.hpp"

int main(int argc, char** argv) {
  using namespace arbor::bench_ad;
#define ARBOR_ROBOT(name, Struct) \
  register_##name();              \
  register_generated_##name();
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
