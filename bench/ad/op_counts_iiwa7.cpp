// Operation counts of Iiwa7 (one robot per translation unit).
#include <robots/iiwa7.hpp>

#include "op_counts.hpp"

arbor::bench_ad::OpCounts arbor::bench_ad::op_counts_iiwa7() {
  return op_counts<arbor::robots::Iiwa7, false>();
}
