// Jacobian (and Hessian) timings of Iiwa7 (one robot per translation unit).
#include <robots/iiwa7.hpp>

#include "jacobian_bench.hpp"

void arbor::bench_ad::register_iiwa7() {
  register_robot<arbor::robots::Iiwa7, false>("iiwa7");
}
