// Jacobian (and Hessian) timings of KinovaGen3 (one robot per translation unit).
#include <robots/kinova_gen3.hpp>

#include "jacobian_bench.hpp"

void arbor::bench_ad::register_kinova_gen3() {
  register_robot<arbor::robots::KinovaGen3, true>("kinova_gen3");
}
