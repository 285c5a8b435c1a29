// Operation counts of KinovaGen3 (one robot per translation unit).
#include <robots/kinova_gen3.hpp>

#include "op_counts.hpp"

arbor::bench_ad::OpCounts arbor::bench_ad::op_counts_kinova_gen3() {
  return op_counts<arbor::robots::KinovaGen3, true>();
}
