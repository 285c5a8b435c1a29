// Shared by the two units of qp_robustness_test: a cold solve (setup, cold start, solve) with
// allocation checking on.
#pragma once

#include "alloc_guard.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp::test {

/// setup(p, set), cold_start() and solve() in a NoAllocScope; the setup's status if rejected.
template <typename Solver, typename Problem, typename Settings>
QpStatus cold_solve(Solver& s, const Problem& p, const Settings& set) {
  arbor::test::NoAllocScope guard;
  const QpStatus st = s.setup(p, set);
  if (st != QpStatus::accepted)
    return st;
  s.cold_start();
  return s.solve();
}

}  // namespace arbor::qp::test
