// Jacobian (and Hessian) timings of Atlas (one robot per translation unit).
#include <robots/atlas.hpp>

#include "jacobian_bench.hpp"

void arbor::bench_ad::register_atlas() {
  register_robot<arbor::robots::Atlas, false>("atlas");
}
