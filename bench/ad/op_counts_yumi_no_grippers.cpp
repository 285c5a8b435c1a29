// Operation counts of YumiNoGrippers (one robot per translation unit).
#include <robots/yumi_no_grippers.hpp>

#include "op_counts.hpp"

arbor::bench_ad::OpCounts arbor::bench_ad::op_counts_yumi_no_grippers() {
  return op_counts<arbor::robots::YumiNoGrippers, false>();
}
