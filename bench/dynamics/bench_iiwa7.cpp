// Benchmarks of every algorithm on Iiwa7 (double and float).
#include <robots/iiwa7.hpp>

#include "bench_register.hpp"

ARBOR_BENCH_ROBOT(arbor::robots::Iiwa7, iiwa7)
