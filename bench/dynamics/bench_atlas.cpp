// Benchmarks of every algorithm on Atlas (double and float).
#include <robots/atlas.hpp>

#include "bench_register.hpp"

ARBOR_BENCH_ROBOT(arbor::robots::Atlas, atlas)
