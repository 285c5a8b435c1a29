// The Generated provider executes exactly the operations it emits (no dense-direction waste): the
// double pendulum's generated Jacobians and Hessians run at arbor::ad::Counted, and the executed
// tally equals the count the generator wrote into the header, the live count (an OpTape: nothing
// executed is dead), and the numbers pinned here. A regression to dense execution, or a change
// of the generator's folding, changes these numbers.
#include <gtest/gtest.h>

#include <cmath>

#include <robots/double_pendulum_ad.hpp>
#include <robots/double_pendulum_ad_hessian.hpp>
#include <tiny_ad.hpp>
#include <vector>

#include "alloc_guard.hpp"
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
  {
    arbor::test::NoAllocScope guard;
    run();
  }
  tape.stop();
  ASSERT_FALSE(tape.overflowed());
  std::vector<std::uint64_t> ids;
  for (int i = 0; i < nout; ++i)
    ids.push_back(out[i].id());
  EXPECT_EQ(ad::op_tally().total(), expected);
  EXPECT_EQ(tape.live(ids, live_flags).total(), expected);
}

// The generator on y0 = x0 x1 + sin(x0), y1 = x2 / x1 (generated_tiny_function.hpp), counted by
// hand from the differentiation rules of gen/ad/adgen.hpp (products with a constant 1 fold, an
// operation on the same operands is one node):
//   primal:           x0*x1, sin(x0), (x0*x1)+sin(x0), x2/x1                 4 (mul, sin, add, div)
//   forward, dx0:     d(x0 x1) = x1 (free), d sin = cos(x0), x1 + cos(x0)    2 (cos, add)
//   forward, dx1:     d(x0 x1) = x0 (free); d(x2/x1) = -(y1 * (1/x1)):
//                     1/x1, y1 * (1/x1), negation                             3 (div, mul, neg)
//   forward, dx2:     d(x2/x1) = 1/x1 (the node above)                        0
//   reverse instead:  y0: cos(x0), cos(x0) + x1 (2); y1: 1/x1, y1*(1/x1), negation (3)
// Both modes 9; the generator keeps forward on a tie. By kind: add 2, mul 2, div 2, neg 1, sin 1,
// cos 1. Executing the zero directions, dead code or unfolded products with 1 would add to these.
template <class G>
void tiny_function_counts() {
  static_assert(G::available);
  EXPECT_EQ(G::primal_ops, 4);
  EXPECT_EQ(G::jacobian_ops, 9);
  const double xv[3] = {0.7, -1.3, 2.1};
  ad::Counted x[3], out[2 + 2 * 3];
  for (int i = 0; i < 3; ++i)
    x[i] = ad::Counted::input(xv[i]);
  expect_counts([&] { G::jacobian(x, out, out + 2); }, out, 2 + 2 * 3, 9);
  const ad::OpTally t = ad::op_tally();
  EXPECT_EQ(t.add, 2u);
  EXPECT_EQ(t.mul, 2u);
  EXPECT_EQ(t.div, 2u);
  EXPECT_EQ(t.neg, 1u);
  EXPECT_EQ(t.sin, 1u);
  EXPECT_EQ(t.cos, 1u);
  EXPECT_EQ(t.sqrt, 0u);
  // The values, against the derivatives by hand (J column major, 2 x 3).
  const double y1 = xv[2] / xv[1];
  const double expected[8] = {xv[0] * xv[1] + std::sin(xv[0]),
                              y1,
                              xv[1] + std::cos(xv[0]),
                              0.0,
                              xv[0],
                              -y1 / xv[1],
                              0.0,
                              1.0 / xv[1]};
  for (int i = 0; i < 8; ++i)
    EXPECT_NEAR(out[i].value(), expected[i], 1e-15) << "entry " << i;
}

TEST(AdGeneratedCount, TinyFunctionExecutesTheHandCountedOperations) {
  tiny_function_counts<ad::GeneratedCode<ad::test::TinyFunction>>();
}

// The same code split into parts of 2 operations (5 parts, values passed through the entry
// function's array): the same 9 operations, nothing added by the split, the same values.
TEST(AdGeneratedCount, ChunkedTinyFunctionExecutesTheSameOperations) {
  tiny_function_counts<ad::GeneratedCode<ad::test::TinyFunctionChunked>>();
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
  // FD's Jacobian goes through ID (before d149038 fd_value 90 + jacobian_at 199: the generator
  // keeps it when it needs fewer operations than differentiating aba, 307 here). The pinned sizes
  // are the generator's output; they change when the traced templates do (d149038, dynamics at the
  // scalar level: 289 -> 286, 500 -> 642, 181 -> 179; the ID Hessian unchanged): update them
  // knowingly.
  check<ad::ForwardDynamics<R>>(286, 642);
  check<ad::InverseDynamics<R>>(179, 279);
}
