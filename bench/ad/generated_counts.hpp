// Operation counts of the generated code (gen/ad) of the benchmark robots, for the paper's
// Table 1 and Table 2 beside arbor's other counts: as the generator wrote them into the headers.
// The generated code executes exactly these (every emitted operation is live and runs once;
// tests/ad/generated_count_test.cpp checks it at arbor::ad::Counted on the double pendulum).
#pragma once

#include <arbor/ad/provider.hpp>

namespace arbor::bench_ad {

/// Operations of one robot's generated code: FD and ID values (live, as traced), Jacobians,
/// Hessians (0 if not generated).
struct GeneratedCounts {
  long fd, jfd, id, jid, hfd, hid;
};

/// Operations of F's generated Hessian (0 if none was generated).
template <class F>
long hessian_ops() {
  if constexpr (ad::GeneratedHessian<F>::available)
    return ad::GeneratedHessian<F>::hessian_ops;
  else
    return 0;
}

#define ARBOR_ROBOT(name, Struct) GeneratedCounts generated_counts_##name();
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT

}  // namespace arbor::bench_ad
