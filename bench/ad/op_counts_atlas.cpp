// Operation counts of Atlas (one robot per translation unit).
#include <robots/atlas.hpp>

#include "op_counts.hpp"

arbor::bench_ad::OpCounts arbor::bench_ad::op_counts_atlas() {
  return op_counts<arbor::robots::Atlas, false>();
}
