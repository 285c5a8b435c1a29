// Operation counts of DoublePendulum (one robot per translation unit).
#include <robots/double_pendulum.hpp>

#include "op_counts.hpp"

arbor::bench_ad::OpCounts arbor::bench_ad::op_counts_double_pendulum() {
  return op_counts<arbor::robots::DoublePendulum, false>();
}
