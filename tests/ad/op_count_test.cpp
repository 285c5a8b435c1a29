// The operation-counting scalar: hand-counted expressions, every folding rule, Eigen products
// with constant and symbolic entries, and dual numbers over counted values.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <arbor/ad/dual.hpp>
#include "op_count.hpp"

#include "alloc_guard.hpp"

namespace {

using arbor::ad::Counted;
using arbor::ad::op_tally;
using arbor::ad::OpTally;
using arbor::ad::reset_op_tally;

// Runs f with a fresh tally and returns the tally.
template <class F>
OpTally count(F&& f) {
  arbor::test::NoAllocScope guard;
  reset_op_tally();
  f();
  return op_tally();
}

TEST(OpCount, CountsEachOperationByKind) {
  const Counted x = Counted::input(2.0), y = Counted::input(3.0), z = Counted::input(-1.0);
  Counted r;
  OpTally t = count([&] { r = x * y + z; });
  EXPECT_EQ(t.mul, 1u);
  EXPECT_EQ(t.add, 1u);
  EXPECT_EQ(t.total(), 2u);
  EXPECT_DOUBLE_EQ(r.value(), 5.0);
  EXPECT_FALSE(r.is_constant());

  t = count([&] { r = (x - y) / z; });
  EXPECT_EQ(t.add, 1u);
  EXPECT_EQ(t.div, 1u);
  EXPECT_EQ(t.total(), 2u);
  EXPECT_DOUBLE_EQ(r.value(), 1.0);

  t = count([&] { r = -x; });
  EXPECT_EQ(t.neg, 1u);
  EXPECT_EQ(t.total(), 1u);

  t = count([&] { r = arbor::sqrt(x) + arbor::sin(y) * arbor::cos(z); });
  EXPECT_EQ(t.sqrt, 1u);
  EXPECT_EQ(t.sin, 1u);
  EXPECT_EQ(t.cos, 1u);
  EXPECT_EQ(t.mul, 1u);
  EXPECT_EQ(t.add, 1u);
  EXPECT_EQ(t.total(), 5u);
  EXPECT_DOUBLE_EQ(r.value(), std::sqrt(2.0) + std::sin(3.0) * std::cos(-1.0));

  Counted s, c;
  t = count([&] { arbor::sincos(x, s, c); });
  EXPECT_EQ(t.sin, 1u);
  EXPECT_EQ(t.cos, 1u);
  EXPECT_EQ(t.total(), 2u);
  EXPECT_DOUBLE_EQ(s.value(), std::sin(2.0));
  EXPECT_DOUBLE_EQ(c.value(), std::cos(2.0));
}

TEST(OpCount, FoldsLikeASymbolicTool) {
  const Counted x = Counted::input(2.5), y = Counted::input(-4.0);
  const Counted zero(0.0), one(1.0), minus_one(-1.0), two(2.0), three(3.0);
  Counted r;
  // constant op constant
  OpTally t = count([&] { r = two * three + arbor::sqrt(two) - arbor::sin(three) / two; });
  EXPECT_EQ(t.total(), 0u);
  EXPECT_TRUE(r.is_constant());
  EXPECT_DOUBLE_EQ(r.value(), 6.0 + std::sqrt(2.0) - std::sin(3.0) / 2.0);
  // x * 0, 0 * x, 0 / x: constant zero
  t = count([&] { r = x * zero + zero * y + zero / x; });
  EXPECT_EQ(t.total(), 0u);
  EXPECT_TRUE(r.is_constant());
  EXPECT_EQ(r.value(), 0.0);
  // x * 1, 1 * x, x / 1, x + 0, 0 + x, x - 0: the same node
  t = count([&] { r = ((one * (x * one) / one) + zero - zero); });
  EXPECT_EQ(t.total(), 0u);
  EXPECT_EQ(r.id(), x.id());
  t = count([&] { r = zero + x; });
  EXPECT_EQ(t.total(), 0u);
  EXPECT_EQ(r.id(), x.id());
  // x - x and x / x of the same node
  t = count([&] { r = x - x; });
  EXPECT_EQ(t.total(), 0u);
  EXPECT_TRUE(r.is_constant());
  EXPECT_EQ(r.value(), 0.0);
  t = count([&] { r = y / y; });
  EXPECT_EQ(t.total(), 0u);
  EXPECT_TRUE(r.is_constant());
  EXPECT_EQ(r.value(), 1.0);
  // a copy is the same node; a recomputation is not (no common-subexpression elimination)
  const Counted p = x * y;
  const Counted p_copy = p;
  t = count([&] { r = p - p_copy; });
  EXPECT_EQ(t.total(), 0u);
  t = count([&] { r = x * y - x * y; });
  EXPECT_EQ(t.mul, 2u);
  EXPECT_EQ(t.add, 1u);
  EXPECT_EQ(r.value(), 0.0);
  EXPECT_FALSE(r.is_constant());
  // x * -1, -1 * x, x / -1, 0 - x: one negation each
  t = count([&] { r = x * minus_one; });
  EXPECT_EQ(t.neg, 1u);
  EXPECT_EQ(t.total(), 1u);
  t = count([&] { r = minus_one * x; });
  EXPECT_EQ(t.neg, 1u);
  EXPECT_EQ(t.total(), 1u);
  t = count([&] { r = x / minus_one; });
  EXPECT_EQ(t.neg, 1u);
  EXPECT_EQ(t.total(), 1u);
  t = count([&] { r = zero - x; });
  EXPECT_EQ(t.neg, 1u);
  EXPECT_EQ(t.total(), 1u);
  EXPECT_DOUBLE_EQ(r.value(), -2.5);
  // negating or taking functions of constants is free
  t = count([&] { r = -two + arbor::cos(zero); });
  EXPECT_EQ(t.total(), 0u);
  EXPECT_DOUBLE_EQ(r.value(), -1.0);
  // compound assignment follows the same rules
  t = count([&] {
    r = x;
    r *= one;
    r += zero;
    r -= y;
  });
  EXPECT_EQ(t.add, 1u);
  EXPECT_EQ(t.total(), 1u);
}

TEST(OpCount, EigenProductsSkipConstantZerosAndOnes) {
  Eigen::Matrix<Counted, 3, 1> v;
  v << Counted::input(1.0), Counted::input(2.0), Counted::input(3.0);
  Eigen::Matrix<Counted, 3, 3> I = Eigen::Matrix<Counted, 3, 3>::Identity();
  Eigen::Matrix<Counted, 3, 1> r;
  // identity times a symbolic vector: free
  OpTally t = count([&] { r.noalias() = I * v; });
  EXPECT_EQ(t.total(), 0u);
  EXPECT_EQ(r[1].id(), v[1].id());
  // a dense symbolic 3x3 times a vector: 9 mul + 6 add
  Eigen::Matrix<Counted, 3, 3> A;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      A(i, j) = Counted::input(i - 2.0 * j);
  t = count([&] { r.noalias() = A * v; });
  EXPECT_EQ(t.mul, 9u);
  EXPECT_EQ(t.add, 6u);
  EXPECT_EQ(t.total(), 15u);
  EXPECT_DOUBLE_EQ(r[2].value(), 2.0 * 1 + 0.0 * 2 - 2.0 * 3);
  // a rotation about z with constant zeros and one: 4 mul + 2 add
  Eigen::Matrix<Counted, 3, 3> Rz = Eigen::Matrix<Counted, 3, 3>::Zero();
  Rz(0, 0) = Counted::input(0.6);
  Rz(0, 1) = Counted::input(-0.8);
  Rz(1, 0) = Counted::input(0.8);
  Rz(1, 1) = Counted::input(0.6);
  Rz(2, 2) = Counted(1.0);
  t = count([&] { r.noalias() = Rz * v; });
  EXPECT_EQ(t.mul, 4u);
  EXPECT_EQ(t.add, 2u);
  EXPECT_EQ(t.total(), 6u);
  EXPECT_EQ(r[2].id(), v[2].id());
  // dot product of 3-vectors: 3 mul + 2 add
  Counted s;
  t = count([&] { s = v.dot(r); });
  EXPECT_EQ(t.total(), 5u);
}

TEST(OpCount, DualsOverCountedFoldTheirSeeds) {
  using D = arbor::ad::Dual<Counted, 2>;
  const D x = D::variable(Counted::input(0.5), 0);
  const D y = D::variable(Counted::input(-2.0), 1);
  D r;
  // x * y: value 1 mul; d0 = x.v * 0 + 1 * y.v and d1 = x.v * 1 + 0 * y.v fold to copies
  OpTally t = count([&] { r = x * y; });
  EXPECT_EQ(t.mul, 1u);
  EXPECT_EQ(t.total(), 1u);
  EXPECT_EQ(r.d[0].id(), y.v.id());
  EXPECT_EQ(r.d[1].id(), x.v.id());
  // sin(x): one sin and one cos; the derivative along x is the cos itself, along y zero
  t = count([&] { r = arbor::sin(x); });
  EXPECT_EQ(t.sin, 1u);
  EXPECT_EQ(t.cos, 1u);
  EXPECT_EQ(t.total(), 2u);
  EXPECT_DOUBLE_EQ(r.d[0].value(), std::cos(0.5));
  EXPECT_TRUE(r.d[1].is_constant());
  // x * y + x * x: products 1 + 1, value add 1, d0 = y + (x + x) -> 2 adds, d1 = x -> free
  t = count([&] { r = x * y + x * x; });
  EXPECT_EQ(t.mul, 2u);
  EXPECT_EQ(t.add, 3u);
  EXPECT_EQ(t.total(), 5u);
  EXPECT_DOUBLE_EQ(r.d[0].value(), -2.0 + 2 * 0.5);
  EXPECT_DOUBLE_EQ(r.d[1].value(), 0.5);
}

TEST(OpCount, TapeCountsOnlyLiveOperations) {
  static arbor::ad::OpTape<64> tape;
  static bool flags[64];
  const Counted x = Counted::input(2.0), y = Counted::input(3.0);
  Counted out, dead;
  {
    arbor::test::NoAllocScope guard;
    reset_op_tally();
    tape.start();
    const Counted p = x * y;       // live
    dead = arbor::sin(p) + x;      // not an output: dead
    out = p - arbor::sqrt(y) / x;  // live: sqrt, div, sub
    tape.stop();
  }
  EXPECT_EQ(op_tally().total(), 6u);  // mul, sin, add, sqrt, div, sub executed
  EXPECT_EQ(tape.recorded(), 6u);
  EXPECT_FALSE(tape.overflowed());
  const std::uint64_t ids[] = {out.id()};
  const OpTally live = tape.live(ids, flags);
  EXPECT_EQ(live.mul, 1u);
  EXPECT_EQ(live.sqrt, 1u);
  EXPECT_EQ(live.div, 1u);
  EXPECT_EQ(live.add, 1u);
  EXPECT_EQ(live.sin, 0u);
  EXPECT_EQ(live.total(), 4u);
  // both outputs: everything is live
  const std::uint64_t both[] = {out.id(), dead.id()};
  EXPECT_EQ(tape.live(both, flags).total(), 6u);
  // a constant output costs nothing; an input output neither
  const std::uint64_t none[] = {Counted(1.0).id(), x.id()};
  EXPECT_EQ(tape.live(none, flags).total(), 0u);
  // overflow is reported, not silently truncated
  static arbor::ad::OpTape<2> small;
  small.start();
  Counted r = x * y + x;
  r = r * r;
  small.stop();
  EXPECT_TRUE(small.overflowed());
}

}  // namespace
