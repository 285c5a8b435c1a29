// Benchmarks of every algorithm on DoublePendulum (double and float).
#include <robots/double_pendulum.hpp>

#include "bench_register.hpp"

ARBOR_BENCH_ROBOT(arbor::robots::DoublePendulum, double_pendulum)
