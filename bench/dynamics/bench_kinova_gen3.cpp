// Benchmarks of every algorithm on KinovaGen3 (double and float).
#include <robots/kinova_gen3.hpp>

#include "bench_register.hpp"

ARBOR_BENCH_ROBOT(arbor::robots::KinovaGen3, kinova_gen3)
