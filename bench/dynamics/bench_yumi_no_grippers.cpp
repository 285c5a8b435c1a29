// Benchmarks of every algorithm on YumiNoGrippers (double and float).
#include <robots/yumi_no_grippers.hpp>

#include "bench_register.hpp"

ARBOR_BENCH_ROBOT(arbor::robots::YumiNoGrippers, yumi_no_grippers)
