// Jacobian (and Hessian) timings of DoublePendulum (one robot per translation unit).
#include <robots/double_pendulum.hpp>

#include "jacobian_bench.hpp"

void arbor::bench_ad::register_double_pendulum() {
  register_robot<arbor::robots::DoublePendulum, false>("double_pendulum");
}
