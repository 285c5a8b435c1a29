// The Generated provider executes exactly the operations it emits (no dense-direction waste): the
// double pendulum's generated Jacobians and Hessians run at arbor::ad::Counted, and the executed
// tally equals the count the generator wrote into the header, the live count (an OpTape: nothing
// executed is dead), and the numbers pinned here. A regression to dense execution, or a change
// of the generator's folding, changes these numbers.
#include <gtest/gtest.h>

#include <robots/double_pendulum_ad.hpp>
#include <robots/double_pendulum_ad_hessian.hpp>
#include <vector>

#include "op_count.hpp"

namespace {

using namespace arbor;
using R = arbor::robots::DoublePendulum;

ad::OpTape<1 << 14> tape;
bool live_flags[1 << 14];

template <class Run>
void expect_counts(Run&& run, const ad::Counted* out, int nout, std::uint64_t expected) {
  ad::reset_op_tally();
  tape.start();
  run();
  tape.stop();
  ASSERT_FALSE(tape.overflowed());
  std::vector<std::uint64_t> ids;
  for (int i = 0; i < nout; ++i)
    ids.push_back(out[i].id());
  EXPECT_EQ(ad::op_tally().total(), expected);
  EXPECT_EQ(tape.live(ids, live_flags).total(), expected);
}

template <class F>
void check(std::uint64_t jacobian_ops, std::uint64_t hessian_ops) {
  using G = ad::GeneratedCode<F>;
  using GH = ad::GeneratedHessian<F>;
  constexpr int n = F::nin, m = F::nout;
  ad::Counted x[n], lambda[m], out[m + n * n];
  for (int i = 0; i < n; ++i)
    x[i] = ad::Counted::input(0.2 + 0.3 * i);
  for (int i = 0; i < m; ++i)
    lambda[i] = ad::Counted::input(0.7 - 0.4 * i);
  EXPECT_EQ(std::uint64_t(G::jacobian_ops), jacobian_ops);
  EXPECT_EQ(std::uint64_t(GH::hessian_ops), hessian_ops);
  expect_counts([&] { G::jacobian(x, out, out + m); }, out, m + m * n, jacobian_ops);
  expect_counts([&] { GH::hessian(x, lambda, out, out + m); }, out, m + n * n, hessian_ops);
}

}  // namespace

TEST(AdGeneratedCount, DoublePendulumExecutesExactlyTheEmittedOperations) {
  // The paper's Table 1 (CasADi): J_FD^c 292, J_ID^c 162; the dense duals execute 781 and 437.
  check<ad::ForwardDynamics<R>>(307, 500);
  check<ad::InverseDynamics<R>>(181, 279);
}
