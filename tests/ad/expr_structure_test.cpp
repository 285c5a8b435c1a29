// Structure-aware forward mode (arbor/ad/expr/structure.hpp): the directions each node depends
// on, and fn bodies run at a dual of only those directions. Expected values are independent of
// the code under test: direction sets and operation counts written out by hand (a scalar that
// counts every arithmetic operation, zeros included, so dense execution shows), closed-form
// derivatives, and the same body run at the evaluation's own scalar (fn_dense). Every library
// call runs under the allocation guard.
#include <gtest/gtest.h>

#include <arbor/ad/expr.hpp>
#include <cmath>
#include <cstdint>

#include "alloc_guard.hpp"
#include "op_tick.hpp"

namespace {

namespace ad = arbor::ad;
using ad::Tick;
using arbor::test::NoAllocScope;

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int M, int N = M>
using Mat = Eigen::Matrix<double, M, N>;

/// Doubles per SIMD register of this build (the compressed duals round their directions up to
/// whole registers, docs/ad_expressions.md), from the compiler's own macros.
#if defined(__AVX__)
constexpr int kLanes = 4;
#elif defined(__SSE2__) || defined(__ARM_NEON)
constexpr int kLanes = 2;
#else
constexpr int kLanes = 1;
#endif
/// k directions rounded up to whole registers, at most n.
constexpr int rounded(int k, int n) {
  const int r = (k + kLanes - 1) / kLanes * kLanes;
  return r < n ? r : n;
}

constexpr ad::Symbol<0, 6> x;  // argument 0: 6 elements
constexpr ad::Symbol<1, 3> u;  // argument 1: 3 elements
constexpr ad::Symbol<2, 2> p;  // argument 2: a parameter where not differentiated

/// The environment of a Jacobian with respect to (x, u) (9 directions), p a parameter.
using Env9 = decltype(ad::detail::jacobian_env<0, 1>(Vec<6>::Zero().eval(), Vec<3>::Zero().eval(),
                                                     Vec<2>::Zero().eval()));

template <class E>
constexpr std::array<bool, 9> deps9(const E&) {
  return ad::detail::deps_of<Env9, E>();
}
constexpr std::array<bool, 9> dirs(std::initializer_list<int> ks) {
  std::array<bool, 9> r{};
  for (int k : ks)
    r[std::size_t(k)] = true;
  return r;
}

TEST(ExprStructure, DirectionSetsFollowTheArguments) {
  // x occupies directions 0..5, u 6..8; p is a parameter
  EXPECT_EQ(deps9(x), dirs({0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(deps9(u), dirs({6, 7, 8}));
  EXPECT_EQ(deps9(p), dirs({}));
  EXPECT_EQ(deps9(ad::segment<2, 3>(x)), dirs({2, 3, 4}));
  EXPECT_EQ(deps9(ad::element<1>(u)), dirs({7}));
  EXPECT_EQ(deps9(ad::constant(Vec<2>(1, 2))), dirs({}));
  EXPECT_EQ(deps9(ad::element<5>(x) * ad::sin(ad::element<0>(u)) + 2.0), dirs({5, 6}));
  EXPECT_EQ(deps9(ad::cat(ad::element<0>(x), p, ad::segment<1, 2>(u))), dirs({0, 7, 8}));
  EXPECT_EQ(deps9(ad::dot(ad::segment<0, 2>(x), p)), dirs({0, 1}));
  EXPECT_EQ(deps9(ad::squared_norm(ad::segment<4, 2>(x) - p)), dirs({4, 5}));
  // a segment of something else than a symbol keeps its operand's set
  EXPECT_EQ(deps9(ad::segment<0, 1>(ad::cat(ad::element<3>(x), ad::element<2>(u)))), dirs({3, 8}));
  // fn: the union of its arguments
  const auto f = ad::fn<1>([](const auto& a, const auto& b) { return a[0] * b[0]; },
                           ad::element<3>(x), ad::element<2>(u));
  EXPECT_EQ(deps9(f), dirs({3, 8}));
  // a let placeholder is not analysed: every direction (a superset is always allowed)
  const auto l = ad::let(ad::element<0>(u), [](auto v) { return v * v; });
  EXPECT_EQ(deps9(l), dirs({0, 1, 2, 3, 4, 5, 6, 7, 8}));
}

TEST(ExprStructure, RowPatternsFollowTheStackedParts) {
  // row patterns (ocp/linearize.hpp's Gauss-Newton products use them): a cat stacks its parts'
  // rows; a seeded symbol's (or segment's) row has its one direction; any other node's rows have
  // the node's directions; a parameter's rows none. Written out by hand.
  const auto e = ad::cat(ad::element<5>(x) * ad::sin(ad::element<0>(u)), ad::segment<1, 2>(u), p,
                         ad::segment<3, 2>(x), ad::segment<0, 1>(ad::cat(x, u)), ad::element<2>(x));
  using E = std::remove_cvref_t<decltype(e)>;
  constexpr auto rows = ad::detail::row_deps<Env9, E>();
  static_assert(rows.size() == 9);
  EXPECT_EQ(rows[0], dirs({5, 6}));
  EXPECT_EQ(rows[1], dirs({7}));
  EXPECT_EQ(rows[2], dirs({8}));
  EXPECT_EQ(rows[3], dirs({}));
  EXPECT_EQ(rows[4], dirs({}));
  EXPECT_EQ(rows[5], dirs({3}));
  EXPECT_EQ(rows[6], dirs({4}));
  EXPECT_EQ(rows[7], dirs({0, 1, 2, 3, 4, 5, 6, 7, 8}));  // a segment of a cat: the cat's set
  EXPECT_EQ(rows[8], dirs({2}));                          // a one-row segment of a symbol
  constexpr auto one = ad::detail::row_deps<Env9, decltype(ad::element<2>(x))>();
  static_assert(one.size() == 1);
  EXPECT_EQ(one[0], dirs({2}));
  constexpr auto pat = ad::detail::row_pattern<9, 9>(rows);
  EXPECT_EQ(pat.count[0], 2);
  EXPECT_EQ(pat.cols[0][0], 5);
  EXPECT_EQ(pat.cols[0][1], 6);
  EXPECT_EQ(pat.count[3], 0);
  EXPECT_EQ(pat.cols[6][0], 4);
  EXPECT_EQ(pat.count[7], 9);
  EXPECT_EQ(pat.count[8], 1);
  // every entry of the Jacobian outside the pattern is zero; inside it (every row but 7, where
  // the pattern is exact) none is at this point
  Vec<6> xv;
  xv << 0.3, -0.7, 1.1, 0.4, -0.2, 0.9;
  const Vec<3> uv(0.5, -1.3, 0.8);
  const Vec<2> pv(2.0, -3.0);
  NoAllocScope guard;
  const Mat<9, 9> J = ad::jacobian<0, 1>(e, xv, uv, pv);
  for (int i = 0; i < 9; ++i) {
    for (int k = 0; k < 9; ++k) {
      if (!rows[std::size_t(i)][std::size_t(k)]) {
        EXPECT_EQ(J(i, k), 0.0) << i << "," << k;
      } else if (i != 7) {
        EXPECT_NE(J(i, k), 0.0) << i << "," << k;
      }
    }
  }
  EXPECT_EQ(J(7, 0), 1.0);
}

/// f(a, b) = [a0 a1 sin(b0), a0^2 + b0 a2] with a = x[1..3], b = u[2].
struct Body {
  int* directions = nullptr;  // records the body's scalar's number of directions (outer level)
  template <class A, class B>
  auto operator()(const A& a, const B& b) const {
    using S = ad::ScalarOf<A>;
    if constexpr (ad::is_dual_v<S>)
      *directions = S::directions;
    else
      *directions = 0;
    arbor::VecN<S, 2> r;
    r[0] = a[0] * a[1] * arbor::sin(b[0]);
    r[1] = a[0] * a[0] + b[0] * a[2];
    return r;
  }
};

TEST(ExprStructure, FnBodyRunsAtTheDirectionsItsArgumentsDependOn) {
  int dirs_seen = -1;
  const auto e = ad::fn<2>(Body{&dirs_seen}, ad::segment<1, 3>(x), ad::element<2>(u));
  const auto e_dense = ad::fn_dense<2>(Body{&dirs_seen}, ad::segment<1, 3>(x), ad::element<2>(u));
  const Vec<6> xv(0.3, -0.7, 1.1, 0.4, -2.0, 0.9);
  const Vec<3> uv(0.2, -0.5, 0.8);
  const Vec<2> pv(1.0, 2.0);
  ad::ValueJacobian<double, 2, 9> vj, vj_dense;
  int seen = -1, seen_dense = -1;
  {
    NoAllocScope guard;
    vj = ad::value_and_jacobian<0, 1>(e, xv, uv, pv);
    seen = dirs_seen;
    vj_dense = ad::value_and_jacobian<0, 1>(e_dense, xv, uv, pv);
    seen_dense = dirs_seen;
  }
  EXPECT_EQ(seen, rounded(4, 9));  // x1, x2, x3, u2
  EXPECT_EQ(seen_dense, 9);
  // closed form
  const double a0 = xv[1], a1 = xv[2], a2 = xv[3], b = uv[2];
  Mat<2, 9> J = Mat<2, 9>::Zero();
  J(0, 1) = a1 * std::sin(b);
  J(0, 2) = a0 * std::sin(b);
  J(0, 8) = a0 * a1 * std::cos(b);
  J(1, 1) = 2 * a0;
  J(1, 3) = b;
  J(1, 8) = a2;
  EXPECT_NEAR(vj.value[0], a0 * a1 * std::sin(b), 1e-15);
  EXPECT_NEAR(vj.value[1], a0 * a0 + b * a2, 1e-15);
  EXPECT_LE((vj.jacobian - J).cwiseAbs().maxCoeff(), 1e-15);
  // the same arithmetic on the kept directions: bitwise equal to the dense run
  EXPECT_EQ(vj.jacobian, vj_dense.jacobian);
  EXPECT_EQ(vj.value, vj_dense.value);
}

TEST(ExprStructure, HessiansCompressBothLevels) {
  int dirs_seen = -1;
  const auto e = ad::sum(ad::fn<2>(Body{&dirs_seen}, ad::segment<1, 3>(x), ad::element<2>(u)));
  const Vec<6> xv(0.3, -0.7, 1.1, 0.4, -2.0, 0.9);
  const Vec<3> uv(0.2, -0.5, 0.8);
  const Vec<2> pv(1.0, 2.0);
  ad::ValueGradientHessian<double, 9> r;
  {
    NoAllocScope guard;
    r = ad::value_gradient_hessian<0, 1>(e, xv, uv, pv);
  }
  EXPECT_EQ(dirs_seen, rounded(4, 9));
  // closed form of a0 a1 sin(b) + a0^2 + b a2 (indices 1, 2, 3 of x; 8 = u2)
  const double a0 = xv[1], a1 = xv[2], a2 = xv[3], b = uv[2];
  Mat<9> H = Mat<9>::Zero();
  H(1, 1) = 2;
  H(1, 2) = H(2, 1) = std::sin(b);
  H(1, 8) = H(8, 1) = a1 * std::cos(b);
  H(2, 8) = H(8, 2) = a0 * std::cos(b);
  H(8, 8) = -a0 * a1 * std::sin(b);
  H(3, 8) = H(8, 3) = 1;
  Vec<9> g = Vec<9>::Zero();
  g[1] = a1 * std::sin(b) + 2 * a0;
  g[2] = a0 * std::sin(b);
  g[3] = b;
  g[8] = a0 * a1 * std::cos(b) + a2;
  EXPECT_NEAR(r.value, a0 * a1 * std::sin(b) + a0 * a0 + b * a2, 1e-15);
  EXPECT_LE((r.gradient - g).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((r.hessian - H).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ExprStructure, ParameterOnlyBodyRunsWithoutDuals) {
  int dirs_seen = -1;
  // the body reads p (a parameter) only: it runs at the plain scalar; its derivatives are zero
  const auto e = ad::fn<2>(Body{&dirs_seen}, ad::cat(p, ad::constant(0.5)), ad::element<1>(p)) +
                 ad::segment<0, 2>(x);
  const Vec<6> xv(0.3, -0.7, 1.1, 0.4, -2.0, 0.9);
  const Vec<3> uv(0.2, -0.5, 0.8);
  const Vec<2> pv(1.5, 2.5);
  ad::ValueJacobian<double, 2, 9> vj;
  {
    NoAllocScope guard;
    vj = ad::value_and_jacobian<0, 1>(e, xv, uv, pv);
  }
  EXPECT_EQ(dirs_seen, 0);
  Mat<2, 9> J = Mat<2, 9>::Zero();
  J(0, 0) = J(1, 1) = 1;
  EXPECT_EQ(vj.jacobian, J);
  EXPECT_NEAR(vj.value[0], 1.5 * 2.5 * std::sin(2.5) + xv[0], 1e-15);
  EXPECT_NEAR(vj.value[1], 1.5 * 1.5 + 2.5 * 0.5 + xv[1], 1e-15);
}

/// Operations of one evaluation of e at the given arguments (Jacobian or Hessian).
template <class F>
std::uint64_t ops(F&& f) {
  ad::reset_tick_count();
  f();
  return ad::tick_count();
}

TEST(ExprStructure, ExecutedOperationsFollowTheKeptDirections) {
  // body a0 * b0: one dual product, 1 + 3K operations at Dual<Tick, K> (value 1 mul; per
  // direction 2 mul + 1 add); nothing else in the tree does arithmetic. Arguments x (6), u (3):
  // 2 of n = 9 directions kept, K = 2 rounded up to whole SIMD registers.
  constexpr std::uint64_t K = std::uint64_t(rounded(2, 9)), n = 9;
  const auto body = [](const auto& a, const auto& b) { return a[0] * b[0]; };
  const auto e = ad::fn<1>(body, ad::element<4>(x), ad::element<0>(u));
  const auto e_dense = ad::fn_dense<1>(body, ad::element<4>(x), ad::element<0>(u));
  using TVec6 = Eigen::Matrix<Tick, 6, 1>;
  using TVec3 = Eigen::Matrix<Tick, 3, 1>;
  TVec6 xt;
  TVec3 ut;
  for (int i = 0; i < 6; ++i)
    xt[i] = Tick(0.1 * (i + 1));
  for (int i = 0; i < 3; ++i)
    ut[i] = Tick(-0.3 * (i + 1));
  std::uint64_t jac = 0, jac_dense = 0, hess = 0, hess_dense = 0;
  ad::ValueJacobian<Tick, 1, 9> vj;
  ad::ValueGradientHessian<Tick, 9> vh;
  {
    NoAllocScope guard;
    jac = ops([&] { vj = ad::value_and_jacobian(e, xt, ut); });
    jac_dense = ops([&] { vj = ad::value_and_jacobian(e_dense, xt, ut); });
    hess = ops([&] { vh = ad::value_gradient_hessian(e, xt, ut); });
    hess_dense = ops([&] { vh = ad::value_gradient_hessian(e_dense, xt, ut); });
  }
  EXPECT_EQ(jac, 1 + 3 * K);        // 7 without SIMD
  EXPECT_EQ(jac_dense, 1 + 3 * n);  // 28
  // at Dual<Dual<Tick, K>, K>: the outer product is 1 + 3K inner products or sums of
  // Dual<Tick, K>: 1 product (1 + 3K), per direction 2 products and 1 sum (1 + K):
  // 1 + 6K + 7K^2
  EXPECT_EQ(hess, 1u + 6u * 2u + 7u * 4u);         // 41
  EXPECT_EQ(hess_dense, 1u + 6u * 9u + 7u * 81u);  // 622
  EXPECT_DOUBLE_EQ(vh.hessian(4, 6).x, 1.0);
  EXPECT_DOUBLE_EQ(vh.hessian(6, 4).x, 1.0);
  EXPECT_DOUBLE_EQ(vh.hessian(4, 4).x, 0.0);
  EXPECT_DOUBLE_EQ(vh.gradient[4].x, ut[0].x);
}

}  // namespace
