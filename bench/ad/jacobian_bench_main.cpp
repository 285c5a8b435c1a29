// Driver of the AD timings (bench/ad/jacobian_bench.hpp).
#include "jacobian_bench.hpp"

int main(int argc, char** argv) {
  using namespace arbor::bench_ad;
  register_double_pendulum();
  register_iiwa7();
  register_kinova_gen3();
  register_yumi_no_grippers();
  register_atlas();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
