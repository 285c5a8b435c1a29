// A problem definition whose stage compares traced values (a kink in its cost residual, chosen by
// the sign of x): the stage generator must refuse it with a message (tests/ocp/CMakeLists.txt runs
// the generator as a test that expects the failure and the message).
#pragma once

#include "arbor/ad/expr.hpp"
#include "arbor/ocp/outer.hpp"
#include "arbor/ocp/problem.hpp"

namespace ocp_test {

/// r = x > 0 ? x : x / 2 (a branch on the traced value).
struct Kink {
  template <class X>
  auto operator()(const X& x) const {
    using S = arbor::ad::ScalarOf<X>;
    arbor::VecN<S, 1> r;
    r[0] = x[0] > S(0) ? S(x[0]) : S(0.5) * x[0];
    return r;
  }
};

struct BranchingStage {
  template <class T>
  struct Workspace {};
  template <class W>
  static auto problem(W&) {
    namespace ocp = arbor::ocp;
    using D = ocp::Dims<1, 1, 1, 3>;
    return ocp::make_problem<D>(
        D::x + 0.1 * D::u, ocp::path_costs(ocp::least_squares(arbor::ad::fn<1>(Kink{}, D::x), 1.0)),
        ocp::terminal_costs(ocp::least_squares(D::x, 1.0)));
  }
};

}  // namespace ocp_test
