// Jacobian (and Hessian) timings of YumiNoGrippers (one robot per translation unit).
#include <robots/yumi_no_grippers.hpp>

#include "jacobian_bench.hpp"

void arbor::bench_ad::register_yumi_no_grippers() {
  register_robot<arbor::robots::YumiNoGrippers, false>("yumi_no_grippers");
}
