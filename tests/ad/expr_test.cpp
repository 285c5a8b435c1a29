// The expression-template layer (arbor/ad/expr.hpp). Expected values are independent of the code
// under test: closed-form derivatives written out here, a hand chain rule through an RK4 step,
// central finite differences of plain double functions, and the analytical RBD derivative
// routines called directly. Custom-derivative nodes: the Jacobian provider is made observable
// with the operation counter (the Analytical tag costs exactly the analytical routine, the
// AutoDiff tag exactly the dual pass through the RBD templates), and both providers agree.
// Every library call runs under the allocation guard.
#include <gtest/gtest.h>

#include <algorithm>
#include <arbor/ad/expr.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <cmath>
#include <cstdint>
#include <memory>
#include <robots/double_pendulum.hpp>
#include <robots/kinova_gen3.hpp>
#include <type_traits>

#include "../dynamics/check_helpers.hpp"
#include "alloc_guard.hpp"
#include "op_count.hpp"

namespace {

namespace ad = arbor::ad;
using arbor::test::NoAllocScope;
using DP = arbor::robots::DoublePendulum;
using Kinova = arbor::robots::KinovaGen3;

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int M, int N = M>
using Mat = Eigen::Matrix<double, M, N>;
template <int N>
using CVec = Eigen::Matrix<ad::Counted, N, 1>;

/// max |H - H^T| relative to max(1, max |H|).
template <class M>
double asymmetry(const M& H) {
  const double scale = std::max(1.0, H.cwiseAbs().maxCoeff());
  return (H - H.transpose()).cwiseAbs().maxCoeff() / scale;
}

/// Counted inputs with the values of x.
template <int N>
CVec<N> counted_inputs(const Vec<N>& x) {
  CVec<N> c;
  for (int i = 0; i < N; ++i)
    c[i] = ad::Counted::input(x[i]);
  return c;
}

/// Dual<Counted, K> variables seeded along directions offset .. offset + N - 1.
template <int K, int N>
Eigen::Matrix<ad::Dual<ad::Counted, K>, N, 1> seeded(const CVec<N>& x, int offset) {
  Eigen::Matrix<ad::Dual<ad::Counted, K>, N, 1> r;
  for (int i = 0; i < N; ++i)
    r[i] = ad::Dual<ad::Counted, K>::variable(x[i], offset + i);
  return r;
}

// ---- (b) closed forms: norms, dot, constant matrices, elementwise functions --------------------

TEST(ExprClosedForm, SquaredNormAndDot) {
  constexpr ad::Symbol<0, 4> x;
  constexpr ad::Symbol<1, 4> y;
  const Vec<4> xv(0.3, -1.2, 0.7, 2.0), yv(-0.4, 0.9, 1.5, -0.6), c(1.0, 2.0, -1.0, 0.5);

  // |x|^2: gradient 2x, Hessian 2I
  ad::ValueGradientHessian<double, 4> n2;
  ARBOR_EXPECT_NO_ALLOC(n2 = ad::value_gradient_hessian(ad::squared_norm(x), xv));
  EXPECT_NEAR(n2.value, 0.09 + 1.44 + 0.49 + 4.0, 1e-14);
  ARBOR_EXPECT_REL(n2.gradient, (2.0 * xv).eval(), 1e-15);
  ARBOR_EXPECT_REL(n2.hessian, (2.0 * Mat<4>::Identity()).eval(), 1e-15);

  // |x - c|^2 (constant vector): gradient 2 (x - c), Hessian 2I
  ad::ValueGradientHessian<double, 4> d2;
  ARBOR_EXPECT_NO_ALLOC(d2 = ad::value_gradient_hessian(ad::squared_norm(x - ad::constant(c)), xv));
  EXPECT_NEAR(d2.value, (xv - c).squaredNorm(), 1e-14);
  ARBOR_EXPECT_REL(d2.gradient, (2.0 * (xv - c)).eval(), 1e-15);
  ARBOR_EXPECT_REL(d2.hessian, (2.0 * Mat<4>::Identity()).eval(), 1e-15);

  // x^T y with respect to (x, y): gradient (y, x), Hessian [0 I; I 0]
  ad::ValueGradientHessian<double, 8> xy;
  ARBOR_EXPECT_NO_ALLOC(xy = ad::value_gradient_hessian(ad::dot(x, y), xv, yv));
  EXPECT_NEAR(xy.value, -0.12 - 1.08 + 1.05 - 1.2, 1e-14);
  Vec<8> g_xy;
  g_xy << yv, xv;
  Mat<8> H_xy = Mat<8>::Zero();
  H_xy.topRightCorner<4, 4>() = Mat<4>::Identity();
  H_xy.bottomLeftCorner<4, 4>() = Mat<4>::Identity();
  ARBOR_EXPECT_REL(xy.gradient, g_xy, 1e-15);
  ARBOR_EXPECT_REL(xy.hessian, H_xy, 1e-15);

  // with respect to y only, and to (y, x) in that order
  Vec<4> g_y;
  Vec<8> g_yx;
  {
    NoAllocScope guard;
    g_y = ad::gradient<1>(ad::dot(x, y), xv, yv);
    g_yx = ad::gradient<1, 0>(ad::dot(x, y), xv, yv);
  }
  ARBOR_EXPECT_REL(g_y, xv, 1e-15);
  Vec<8> g_yx_ref;
  g_yx_ref << xv, yv;
  ARBOR_EXPECT_REL(g_yx, g_yx_ref, 1e-15);

  // c^T x (constant weights): gradient c, Hessian 0
  ad::ValueGradientHessian<double, 4> w;
  ARBOR_EXPECT_NO_ALLOC(w = ad::value_gradient_hessian(ad::dot(ad::constant(c), x), xv));
  EXPECT_NEAR(w.value, 0.3 - 2.4 - 0.7 + 1.0, 1e-14);
  ARBOR_EXPECT_REL(w.gradient, c, 1e-15);
  ARBOR_EXPECT_REL(w.hessian, Mat<4>::Zero().eval(), 0.0);
}

// K has structural zeros, +-1 entries and a zero row: a type with a static constexpr array.
struct K34 {
  static constexpr int rows = 3;
  static constexpr int cols = 4;
  static constexpr double entries[12] = {1.0, 0.0, -1.0, 0.0,  //
                                         0.0, 2.0, 0.0,  0.5,  //
                                         0.0, 0.0, 0.0,  0.0};
  static constexpr double at(int r, int c) { return entries[r * cols + c]; }
};

Mat<3, 4> k34_values() {
  Mat<3, 4> K;
  K << 1.0, 0.0, -1.0, 0.0,  //
      0.0, 2.0, 0.0, 0.5,    //
      0.0, 0.0, 0.0, 0.0;
  return K;
}

TEST(ExprClosedForm, ConstantMatrixProducts) {
  constexpr ad::Symbol<0, 4> x;
  constexpr ad::Symbol<1, 3> z;
  const Vec<4> xv(0.3, -1.2, 0.7, 2.0);
  const Vec<3> b(0.5, -0.25, 1.0), zv(0.2, 0.4, -0.8);
  const Mat<3, 4> K = k34_values();

  Vec<3> kx, kx2, kx3;
  Mat<3, 4> J, J2;
  Mat<4, 3> Jt;
  ad::ValueGradientHessian<double, 4> f;
  {
    NoAllocScope guard;
    kx = ad::evaluate(ad::mul<K34>(x), xv);
    kx2 = ad::evaluate(K34{} * x, xv);
#if defined(__cpp_nontype_template_args) && __cpp_nontype_template_args >= 201911L
    using KC = ad::ConstMatrix<3, 4, {1.0, 0.0, -1.0, 0.0, 0.0, 2.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0}>;
    kx3 = ad::evaluate(ad::mul<KC>(x), xv);
#else
    kx3 = kx;
#endif
    J = ad::jacobian(ad::mul<K34>(x), xv);
    J2 = ad::jacobian(K34{} * x, xv);
    Jt = ad::jacobian<1>(ad::mul<ad::TransposedMatrix<K34>>(z), xv, zv);
    f = ad::value_gradient_hessian(ad::squared_norm(ad::mul<K34>(x) - ad::constant(b)), xv);
  }
  const Vec<3> kx_ref(0.3 - 0.7, -2.4 + 1.0, 0.0);
  ARBOR_EXPECT_REL(kx, kx_ref, 1e-15);
  ARBOR_EXPECT_REL(kx2, kx_ref, 1e-15);
  ARBOR_EXPECT_REL(kx3, kx_ref, 1e-15);
  ARBOR_EXPECT_REL(J, K, 0.0);
  ARBOR_EXPECT_REL(J2, K, 0.0);
  ARBOR_EXPECT_REL(Jt, K.transpose().eval(), 0.0);
  // |K x - b|^2: gradient 2 K^T (K x - b), Hessian 2 K^T K
  EXPECT_NEAR(f.value, (kx_ref - b).squaredNorm(), 1e-14);
  ARBOR_EXPECT_REL(f.gradient, (2.0 * K.transpose() * (kx_ref - b)).eval(), 1e-15);
  ARBOR_EXPECT_REL(f.hessian, (2.0 * K.transpose() * K).eval(), 1e-15);
}

TEST(ExprClosedForm, ConstantMatrixZerosCostNothing) {
  // K x costs: row 0 one subtraction (x0 - x2), row 1 two multiplications and one addition,
  // row 2 nothing. With unit seeds the derivative parts are constants and fold: the Jacobian
  // costs the same 4 operations.
  constexpr ad::Symbol<0, 4> x;
  const CVec<4> xc = counted_inputs<4>(Vec<4>(0.3, -1.2, 0.7, 2.0));
  std::uint64_t value_ops = 0, jacobian_ops = 0;
  ad::OpTally t;
  {
    NoAllocScope guard;
    ad::reset_op_tally();
    (void)ad::evaluate(ad::mul<K34>(x), xc);
    t = ad::op_tally();
    value_ops = t.total();
    ad::reset_op_tally();
    (void)ad::jacobian(ad::mul<K34>(x), xc);
    jacobian_ops = ad::op_tally().total();
  }
  EXPECT_EQ(t.add, 2u);
  EXPECT_EQ(t.mul, 2u);
  EXPECT_EQ(value_ops, 4u);
  EXPECT_EQ(jacobian_ops, 4u);
}

TEST(ExprClosedForm, GradientOfDotOpCount) {
  // d/dx x^T x for n = 3 under Counted: value 3 mul + 2 add; derivative k is x_k * 1 + 1 * x_k
  // (one add, the unit products fold), the other terms are 0 and fold: 3 add. Total 8.
  constexpr ad::Symbol<0, 3> x;
  const CVec<3> xc = counted_inputs<3>(Vec<3>(0.5, -1.5, 2.0));
  ad::OpTally t;
  CVec<3> g;
  {
    NoAllocScope guard;
    ad::reset_op_tally();
    g = ad::gradient(ad::dot(x, x), xc);
    t = ad::op_tally();
  }
  EXPECT_EQ(t.mul, 3u);
  EXPECT_EQ(t.add, 5u);
  EXPECT_EQ(t.total(), 8u);
  EXPECT_DOUBLE_EQ(g[1].value(), -3.0);
}

TEST(ExprClosedForm, ElementwiseFunctions) {
  constexpr ad::Symbol<0, 3> x;
  constexpr ad::Symbol<1, 3> y;
  const Vec<3> xv(0.4, -1.1, 2.3), yv(0.8, 1.7, 0.3);  // y > 0
  // e = sin(x) sqrt(y) + cos(x) / y - 3 x
  const auto e = ad::sin(x) * ad::sqrt(y) + ad::cos(x) / y - 3.0 * x;
  ad::ValueJacobian<double, 3, 6> vj;
  ad::ValueGradientHessian<double, 6> f;
  {
    NoAllocScope guard;
    vj = ad::value_and_jacobian(e, xv, yv);
    f = ad::value_gradient_hessian(ad::sum(e), xv, yv);
  }
  Vec<3> val;
  Mat<3, 6> J = Mat<3, 6>::Zero();
  Vec<6> g;
  Mat<6> H = Mat<6>::Zero();
  for (int i = 0; i < 3; ++i) {
    const double s = std::sin(xv[i]), c = std::cos(xv[i]), y = yv[i], r = std::sqrt(y);
    val[i] = s * r + c / y - 3 * xv[i];
    J(i, i) = c * r - s / y - 3;              // d/dx
    J(i, 3 + i) = s / (2 * r) - c / (y * y);  // d/dy
    g[i] = J(i, i);
    g[3 + i] = J(i, 3 + i);
    H(i, i) = -s * r - c / y;                                  // d2/dx2
    H(i, 3 + i) = H(3 + i, i) = c / (2 * r) + s / (y * y);     // d2/dxdy
    H(3 + i, 3 + i) = -s / (4 * y * r) + 2 * c / (y * y * y);  // d2/dy2
  }
  ARBOR_EXPECT_REL(vj.value, val, 1e-15);
  ARBOR_EXPECT_REL(vj.jacobian, J, 1e-14);
  EXPECT_NEAR(f.value, val.sum(), 1e-14);
  ARBOR_EXPECT_REL(f.gradient, g, 1e-14);
  ARBOR_EXPECT_REL(f.hessian, H, 1e-13);

  // -(2 / x) + x * x: Jacobian diag(2 / x^2 + 2 x); Hessian of the sum diag(-4 / x^3 + 2)
  const auto e2 = -(2.0 / x) + x * x;
  Mat<3> J2;
  Mat<3> H2;
  {
    NoAllocScope guard;
    J2 = ad::jacobian(e2, xv);
    H2 = ad::hessian(ad::sum(e2), xv);
  }
  Mat<3> J2_ref = Mat<3>::Zero(), H2_ref = Mat<3>::Zero();
  for (int i = 0; i < 3; ++i) {
    J2_ref(i, i) = 2 / (xv[i] * xv[i]) + 2 * xv[i];
    H2_ref(i, i) = -4 / (xv[i] * xv[i] * xv[i]) + 2;
  }
  ARBOR_EXPECT_REL(J2, J2_ref, 1e-14);
  ARBOR_EXPECT_REL(H2, H2_ref, 1e-14);
}

TEST(ExprClosedForm, SegmentElementConcatenationAndBroadcast) {
  constexpr ad::Symbol<0, 3> x;
  constexpr ad::Symbol<1, 1> s;  // passed as a plain double
  const Vec<3> xv(0.4, -1.1, 2.3);
  const double sv = 1.6;
  // e = (-x2, s x0, s x1, x0 / s, x1 / s, x2 / s, s + 1, 2 - x1)
  const auto e = ad::cat(-ad::element<2>(x), s * ad::segment<0, 2>(x), x / s, s + 1.0,
                         2.0 - ad::element<1>(x));
  static_assert(decltype(e)::rows == 8);
  ad::ValueJacobian<double, 8, 4> vj;
  Mat<8, 1> Js_first;
  Mat<8, 3> Jx;
  {
    NoAllocScope guard;
    vj = ad::value_and_jacobian(e, xv, sv);
    Js_first = ad::jacobian<1>(e, xv, sv);
    Jx = ad::jacobian<0>(e, xv, sv);
  }
  Vec<8> val;
  val << -xv[2], sv * xv[0], sv * xv[1], xv[0] / sv, xv[1] / sv, xv[2] / sv, sv + 1, 2 - xv[1];
  Mat<8, 4> J = Mat<8, 4>::Zero();  // columns x0, x1, x2, s
  J(0, 2) = -1;
  J(1, 0) = sv;
  J(1, 3) = xv[0];
  J(2, 1) = sv;
  J(2, 3) = xv[1];
  for (int i = 0; i < 3; ++i) {
    J(3 + i, i) = 1 / sv;
    J(3 + i, 3) = -xv[i] / (sv * sv);
  }
  J(6, 3) = 1;
  J(7, 1) = -1;
  ARBOR_EXPECT_REL(vj.value, val, 1e-15);
  ARBOR_EXPECT_REL(vj.jacobian, J, 1e-15);
  ARBOR_EXPECT_REL(Js_first, J.col(3).eval(), 1e-15);
  ARBOR_EXPECT_REL(Jx, J.leftCols<3>().eval(), 1e-15);
}

TEST(ExprClosedForm, FloatArguments) {
  constexpr ad::Symbol<0, 2> x;
  const Eigen::Vector2f xf(0.5f, -0.25f);
  Eigen::Vector2f v;
  Eigen::Matrix2f J;
  {
    NoAllocScope guard;
    v = ad::evaluate(ad::sin(x) * 2.0, xf);
    J = ad::jacobian(ad::sin(x) * 2.0, xf);
  }
  EXPECT_NEAR(v[0], 2 * std::sin(0.5), 1e-6);
  EXPECT_NEAR(J(1, 1), 2 * std::cos(-0.25), 1e-6);
  EXPECT_EQ(J(0, 1), 0.0f);
}

// ---- materialisation: let and fn ---------------------------------------------------------------

TEST(ExprLet, MatchesTheDuplicatedExpressionAndEvaluatesOnce) {
  constexpr ad::Symbol<0, 3> x;
  constexpr ad::Symbol<1, 1> s;
  const Vec<3> xv(0.4, -1.1, 2.3);
  const double sv = 0.7;
  const auto shared = ad::let(ad::sin(x) * s, [](auto v) { return v * v + 2.0 * v; });
  const auto duplicated = (ad::sin(x) * s) * (ad::sin(x) * s) + 2.0 * (ad::sin(x) * s);
  ad::ValueGradientHessian<double, 4> a, b;
  {
    NoAllocScope guard;
    a = ad::value_gradient_hessian(ad::sum(shared), xv, sv);
    b = ad::value_gradient_hessian(ad::sum(duplicated), xv, sv);
  }
  EXPECT_NEAR(a.value, b.value, 1e-14);
  ARBOR_EXPECT_REL(a.gradient, b.gradient, 1e-14);
  ARBOR_EXPECT_REL(a.hessian, b.hessian, 1e-14);
  // the shared subexpression is evaluated once: 3 sines instead of 9
  const CVec<3> xc = counted_inputs<3>(xv);
  const ad::Counted sc = ad::Counted::input(sv);
  std::uint64_t sin_shared = 0, sin_duplicated = 0;
  {
    NoAllocScope guard;
    ad::reset_op_tally();
    (void)ad::evaluate(shared, xc, sc);
    sin_shared = ad::op_tally().sin;
    ad::reset_op_tally();
    (void)ad::evaluate(duplicated, xc, sc);
    sin_duplicated = ad::op_tally().sin;
  }
  EXPECT_EQ(sin_shared, 3u);
  EXPECT_EQ(sin_duplicated, 9u);
}

TEST(ExprLet, NestedLets) {
  // let a = x in let b = a * a in b + a  ->  x^2 + x, Jacobian diag(2 x + 1)
  constexpr ad::Symbol<0, 3> x;
  const Vec<3> xv(0.4, -1.1, 2.3);
  const auto e = ad::let(x, [](auto a) { return ad::let(a * a, [a](auto b) { return b + a; }); });
  ad::ValueJacobian<double, 3, 3> vj;
  ARBOR_EXPECT_NO_ALLOC(vj = ad::value_and_jacobian(e, xv));
  ARBOR_EXPECT_REL(vj.value, (xv.array() * xv.array() + xv.array()).matrix().eval(), 1e-15);
  ARBOR_EXPECT_REL(vj.jacobian, (2.0 * xv + Vec<3>::Ones()).asDiagonal().toDenseMatrix().eval(),
                   1e-15);
}

// ---- (a) an RK4 step of a damped, driven pendulum
// ------------------------------------------------ theta'' = -(g / l) sin(theta) - c omega + u,
// state x = (theta, omega), control u.

constexpr double kGl = 9.81 / 0.7;
constexpr double kDamp = 0.3;
constexpr double kH = 0.05;

/// The ODE as plain generic code (double, Dual, Counted).
template <class S>
Eigen::Matrix<S, 2, 1> pendulum_ode(const Eigen::Matrix<S, 2, 1>& x, const S& u) {
  Eigen::Matrix<S, 2, 1> r;
  r[0] = x[1];
  r[1] = S(-kGl) * arbor::sin(x[0]) - S(kDamp) * x[1] + u;
  return r;
}

/// One RK4 step as plain generic code.
template <class S>
Eigen::Matrix<S, 2, 1> rk4_step(const Eigen::Matrix<S, 2, 1>& x, const S& u) {
  using V = Eigen::Matrix<S, 2, 1>;
  const V k1 = pendulum_ode<S>(x, u);
  const V k2 = pendulum_ode<S>(V(x + k1 * S(kH / 2)), u);
  const V k3 = pendulum_ode<S>(V(x + k2 * S(kH / 2)), u);
  const V k4 = pendulum_ode<S>(V(x + k3 * S(kH)), u);
  return V(x + (k1 + k2 * S(2) + k3 * S(2) + k4) * S(kH / 6));
}

/// The ODE as an expression; x is used three times (theta once, omega twice).
template <ad::Expression X, ad::Expression U>
auto pendulum_ode_expr(const X& x, const U& u) {
  const auto theta = ad::element<0>(x);
  const auto omega = ad::element<1>(x);
  return ad::cat(omega, -kGl * ad::sin(theta) - kDamp * omega + u);
}

/// RK4 from expressions with every stage bound once (let).
template <ad::Expression X, ad::Expression U>
auto rk4_let(const X& x, const U& u) {
  return ad::let(pendulum_ode_expr(x, u), [=](auto k1) {
    return ad::let(pendulum_ode_expr(x + (kH / 2) * k1, u), [=](auto k2) {
      return ad::let(pendulum_ode_expr(x + (kH / 2) * k2, u), [=](auto k3) {
        const auto k4 = pendulum_ode_expr(x + kH * k3, u);
        return x + (kH / 6) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      });
    });
  });
}

/// RK4 from expressions without let: each stage re-evaluates the previous ones (3x per stage).
template <ad::Expression X, ad::Expression U>
auto rk4_naive(const X& x, const U& u) {
  const auto k1 = pendulum_ode_expr(x, u);
  const auto k2 = pendulum_ode_expr(x + (kH / 2) * k1, u);
  const auto k3 = pendulum_ode_expr(x + (kH / 2) * k2, u);
  const auto k4 = pendulum_ode_expr(x + kH * k3, u);
  return x + (kH / 6) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
}

/// RK4 as one fn node around the plain generic code.
template <ad::Expression X, ad::Expression U>
auto rk4_fn(const X& x, const U& u) {
  return ad::fn<2>(
      [](const auto& xs, const auto& us) {
        using S = ad::ScalarOf<decltype(xs)>;
        return rk4_step<S>(xs, us[0]);
      },
      x, u);
}

/// d f / d (x, u) of the ODE, by hand: [0 1 0; -(g/l) cos(theta) -c 1].
Mat<2, 3> pendulum_ode_jacobian(const Vec<2>& x) {
  Mat<2, 3> D;
  D << 0.0, 1.0, 0.0, -kGl * std::cos(x[0]), -kDamp, 1.0;
  return D;
}

/// d rk4 / d (x, u) by the chain rule through the four stages, by hand.
Mat<2, 3> rk4_jacobian_by_hand(const Vec<2>& x, double u) {
  Mat<2, 3> dX = Mat<2, 3>::Zero();  // d x / d z
  dX.leftCols<2>() = Mat<2>::Identity();
  Mat<2, 3> dU = Mat<2, 3>::Zero();  // the control's direct contribution b e_u^T
  dU(1, 2) = 1.0;
  auto stage = [&](const Vec<2>& xs, const Mat<2, 3>& dxs) -> Mat<2, 3> {
    const Mat<2, 3> D = pendulum_ode_jacobian(xs);
    return D.leftCols<2>() * dxs + dU;
  };
  const Vec<2> k1 = pendulum_ode<double>(x, u);
  const Mat<2, 3> dk1 = stage(x, dX);
  const Vec<2> x2 = x + kH / 2 * k1;
  const Vec<2> k2 = pendulum_ode<double>(x2, u);
  const Mat<2, 3> dk2 = stage(x2, dX + kH / 2 * dk1);
  const Vec<2> x3 = x + kH / 2 * k2;
  const Vec<2> k3 = pendulum_ode<double>(x3, u);
  const Mat<2, 3> dk3 = stage(x3, dX + kH / 2 * dk2);
  const Vec<2> x4 = x + kH * k3;
  const Mat<2, 3> dk4 = stage(x4, dX + kH * dk3);
  return dX + kH / 6 * (dk1 + 2 * dk2 + 2 * dk3 + dk4);
}

class ExprRk4 : public ::testing::Test {
 protected:
  static constexpr ad::Symbol<0, 2> x{};
  static constexpr ad::Symbol<1, 1> u{};
  const Vec<2> xv{0.9, -0.4};
  const double uv = 0.35;
  const Vec<2> lambda{0.7, -1.3};
};

TEST_F(ExprRk4, StageJacobianIsTheClosedForm) {
  ad::ValueJacobian<double, 2, 3> vj;
  ARBOR_EXPECT_NO_ALLOC(vj = ad::value_and_jacobian(pendulum_ode_expr(x, u), xv, uv));
  const Vec<2> f(xv[1], -kGl * std::sin(xv[0]) - kDamp * xv[1] + uv);
  ARBOR_EXPECT_REL(vj.value, f, 1e-15);
  ARBOR_EXPECT_REL(vj.jacobian, pendulum_ode_jacobian(xv), 1e-15);
}

TEST_F(ExprRk4, JacobianMatchesHandChainRuleAndFiniteDifferences) {
  ad::ValueJacobian<double, 2, 3> a, b, c;
  {
    NoAllocScope guard;
    a = ad::value_and_jacobian(rk4_let(x, u), xv, uv);
    b = ad::value_and_jacobian(rk4_naive(x, u), xv, uv);
    c = ad::value_and_jacobian(rk4_fn(x, u), xv, uv);
  }
  const Vec<2> y = rk4_step<double>(xv, uv);
  const Mat<2, 3> J_hand = rk4_jacobian_by_hand(xv, uv);
  // central differences of the plain double step, h = 1e-6
  Mat<2, 3> J_fd;
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Vec<2> xp = xv, xm = xv;
    double up = uv, um = uv;
    if (k < 2) {
      xp[k] += h;
      xm[k] -= h;
    } else {
      up += h;
      um -= h;
    }
    J_fd.col(k) = (rk4_step<double>(xp, up) - rk4_step<double>(xm, um)) / (2 * h);
  }
  ARBOR_EXPECT_REL(J_hand, J_fd, 1e-8);  // the hand derivation itself
  for (const auto* r : {&a, &b, &c}) {
    ARBOR_EXPECT_REL(r->value, y, 1e-15);
    ARBOR_EXPECT_REL(r->jacobian, J_hand, 1e-13);
  }
}

TEST_F(ExprRk4, HessianMatchesFiniteDifferencesOfTheHandJacobian) {
  // phi(z) = lambda^T rk4(z); Hessian against central differences of lambda^T J_hand(z)
  ad::ValueGradientHessian<double, 3> a, c;
  {
    NoAllocScope guard;
    a = ad::value_gradient_hessian(ad::dot(ad::constant(lambda), rk4_let(x, u)), xv, uv);
    c = ad::value_gradient_hessian(ad::dot(ad::constant(lambda), rk4_fn(x, u)), xv, uv);
  }
  Mat<3> H_fd;
  const double h = 1e-5;
  for (int k = 0; k < 3; ++k) {
    Vec<2> xp = xv, xm = xv;
    double up = uv, um = uv;
    if (k < 2) {
      xp[k] += h;
      xm[k] -= h;
    } else {
      up += h;
      um -= h;
    }
    H_fd.col(k) = ((lambda.transpose() * rk4_jacobian_by_hand(xp, up)).transpose() -
                   (lambda.transpose() * rk4_jacobian_by_hand(xm, um)).transpose()) /
                  (2 * h);
  }
  const Vec<3> g_hand = (lambda.transpose() * rk4_jacobian_by_hand(xv, uv)).transpose();
  for (const auto* r : {&a, &c}) {
    EXPECT_NEAR(r->value, lambda.dot(rk4_step<double>(xv, uv)), 1e-15);
    ARBOR_EXPECT_REL(r->gradient, g_hand, 1e-13);
    ARBOR_EXPECT_REL(r->hessian, H_fd, 1e-8);
    EXPECT_LE(asymmetry(r->hessian), 1e-14);
  }
  ARBOR_EXPECT_REL(a.hessian, c.hessian, 1e-13);
}

TEST_F(ExprRk4, SharedStagesAreEvaluatedOnce) {
  // Four sines per step with let or fn. Without let every stage evaluates its input three
  // times (theta once, omega twice), so stage i costs 1 + 3 (cost of stage i - 1) sines:
  // 1, 4, 13, 40, and the step 1 + 4 + 13 + 40 = 58.
  const CVec<2> xc = counted_inputs<2>(xv);
  const ad::Counted uc = ad::Counted::input(uv);
  std::uint64_t with_let = 0, naive = 0, with_fn = 0;
  {
    NoAllocScope guard;
    ad::reset_op_tally();
    (void)ad::evaluate(rk4_let(x, u), xc, uc);
    with_let = ad::op_tally().sin;
    ad::reset_op_tally();
    (void)ad::evaluate(rk4_naive(x, u), xc, uc);
    naive = ad::op_tally().sin;
    ad::reset_op_tally();
    (void)ad::evaluate(rk4_fn(x, u), xc, uc);
    with_fn = ad::op_tally().sin;
  }
  EXPECT_EQ(with_let, 4u);
  EXPECT_EQ(with_fn, 4u);
  EXPECT_EQ(naive, 58u);
}

// ---- custom-derivative nodes: the function object is an instance (a handle) ---------------------

/// A probe provider tag (the node passes Tag through to the function object).
struct ProbeTag {};

/// What the handle below records in caller-owned storage.
struct ProbeLog {
  double gain = 1.0;            // the function's parameter
  int value_calls = 0;          // value<T> calls
  int jacobian_calls = 0;       // value_and_jacobian<ProbeTag, T> calls
  int dual_jacobian_calls = 0;  // of those, at a Dual T (a Hessian evaluation)
};

/// y = gain * sin(x) (elementwise, 2-vectors) with its Jacobian diag(gain * cos(x)): a handle
/// holding a pointer to caller-owned state, as the RBD function objects bound to a workspace.
struct ScaledSine {
  static constexpr int nin = 2;
  static constexpr int nout = 2;
  ProbeLog* log;
  template <class T>
  void value(const arbor::VecN<T, 2>& x, arbor::VecN<T, 2>& y) const {
    ++log->value_calls;
    for (int i = 0; i < 2; ++i)
      y[i] = T(log->gain) * arbor::sin(x[i]);
  }
  template <class Tag, class T>
  void value_and_jacobian(const arbor::VecN<T, 2>& x, arbor::VecN<T, 2>& y,
                          Eigen::Matrix<T, 2, 2>& J) const {
    static_assert(std::is_same_v<Tag, ProbeTag>);
    ++log->jacobian_calls;
    if constexpr (ad::is_dual_v<T>)
      ++log->dual_jacobian_calls;
    for (int i = 0; i < 2; ++i) {
      y[i] = T(log->gain) * arbor::sin(x[i]);
      J(i, i) = T(log->gain) * arbor::cos(x[i]);
    }
  }
};

TEST(ExprCall, CallsThroughTheStoredHandle) {
  // the node keeps a copy of the handle: state changed through the caller's pointer after the
  // expression is built is seen by every evaluation; value() serves plain evaluations and
  // value_and_jacobian<Tag, T>() derivatives (once, the value from the same pass), at T = Dual
  // for Hessians. References: closed forms of g sin(x).
  constexpr ad::Symbol<0, 2> x;
  const Vec<2> xv(0.3, -1.1);
  ProbeLog log;
  const auto e = ad::call<ProbeTag>(ScaledSine{&log}, x);
  const auto chained = ad::call<ProbeTag>(ScaledSine{&log}, 2.0 * x);
  const auto copy = e;  // copies the handle, not the state
  static_assert(std::is_trivially_copyable_v<ScaledSine>);
  log.gain = 1.5;
  Vec<2> y, y_copy;
  Mat<2> J, J_chained, H;
  ProbeLog after_value, after_jacobian;
  {
    NoAllocScope guard;
    y = ad::evaluate(e, xv);
    after_value = log;
    J = ad::jacobian(e, xv);
    after_jacobian = log;
    J_chained = ad::jacobian(chained, xv);
    H = ad::hessian(ad::sum(e), xv);
    log.gain = 2.5;
    y_copy = ad::evaluate(copy, xv);
  }
  const double g = 1.5;
  ARBOR_EXPECT_REL(y, Vec<2>(g * std::sin(xv[0]), g * std::sin(xv[1])), 1e-15);
  ARBOR_EXPECT_REL(y_copy, Vec<2>(2.5 * std::sin(xv[0]), 2.5 * std::sin(xv[1])), 1e-15);
  Mat<2> J_ref = Mat<2>::Zero(), Jc_ref = Mat<2>::Zero(), H_ref = Mat<2>::Zero();
  for (int i = 0; i < 2; ++i) {
    J_ref(i, i) = g * std::cos(xv[i]);
    Jc_ref(i, i) = 2 * g * std::cos(2 * xv[i]);
    H_ref(i, i) = -g * std::sin(xv[i]);
  }
  ARBOR_EXPECT_REL(J, J_ref, 1e-15);
  ARBOR_EXPECT_REL(J_chained, Jc_ref, 1e-15);
  ARBOR_EXPECT_REL(H, H_ref, 1e-15);
  EXPECT_EQ(after_value.value_calls, 1);
  EXPECT_EQ(after_value.jacobian_calls, 0);
  EXPECT_EQ(after_jacobian.value_calls, 1);  // no value() call for a Jacobian
  EXPECT_EQ(after_jacobian.jacobian_calls, 1);
  EXPECT_EQ(log.jacobian_calls, 3);  // + chained Jacobian + Hessian
  EXPECT_EQ(log.dual_jacobian_calls, 1);
  EXPECT_EQ(log.value_calls, 2);
}

// ---- custom-derivative nodes: the provider tag ------------------------------------------------
// The provider checks run at Counted inputs: Counted carries the double value through the same
// arithmetic (folding x * 1, x + 0 changes no value), so one instantiation per routine gives
// both the numbers and the operation counts. This keeps the translation unit within its
// compile-memory budget (every RBD routine instantiated at another scalar type costs ~100 MB of
// compiler memory); double-valued Jacobians through call nodes are checked below (frame position,
// chain rule, Hessians, path error).

/// The double values of a Counted matrix.
template <int M, int N>
Mat<M, N> values_of(const Eigen::Matrix<ad::Counted, M, N>& a) {
  Mat<M, N> r;
  for (int i = 0; i < M; ++i)
    for (int j = 0; j < N; ++j)
      r(i, j) = a(i, j).value();
  return r;
}

/// Value and Jacobian (double values) and the operation count of one evaluation.
template <int M, int N>
struct Measured {
  Vec<M> value;
  Mat<M, N> jacobian;
  std::uint64_t ops = 0;
};

/// A reference routine's result at Dual<Counted, N>: values and derivatives.
template <int M, int N, class V>
Measured<M, N> from_duals(const V& y) {
  Measured<M, N> r;
  for (int i = 0; i < M; ++i) {
    r.value[i] = y[i].v.value();
    for (int k = 0; k < N; ++k)
      r.jacobian(i, k) = y[i].d[k].value();
  }
  return r;
}

/// Checks call<Analytical> and call<AutoDiff> nodes (ea, ec) at Counted inputs xc... against
/// the plain routine at Counted (value), the analytical routine at Counted and the plain
/// routine at Dual<Counted, nin> with unit seeds (Jacobians), each returning a Measured result:
///   - the Analytical tag gives exactly the analytical routine's numbers and operation count
///     (with unit seeds the chain rule folds to nothing, and the value comes from the same
///     provider call: no separate value() pass);
///   - the AutoDiff tag gives exactly the dual pass's numbers and operation count;
///   - the value-only evaluation costs exactly the plain routine;
///   - the two tags agree to 1e-9 and their counts differ.
template <int M, int N, class EA, class EC, class RV, class RA, class RC, class... X>
void check_providers(const EA& ea, const EC& ec, RV ref_value, RA ref_analytical, RC ref_autodiff,
                     const X&... xc) {
  Measured<M, N> a, c, ra, rc;
  Vec<M> y;
  std::uint64_t value_ops = 0, ref_value_ops = 0;
  Vec<M> ref_y;
  {
    NoAllocScope guard;
    ad::reset_op_tally();
    const auto yv = ad::evaluate(ea, xc...);
    value_ops = ad::op_tally().total();
    y = values_of(yv);
    ad::reset_op_tally();
    const auto va = ad::value_and_jacobian(ea, xc...);
    a.ops = ad::op_tally().total();
    a.value = values_of(va.value);
    a.jacobian = values_of(va.jacobian);
    ad::reset_op_tally();
    const auto vc = ad::value_and_jacobian(ec, xc...);
    c.ops = ad::op_tally().total();
    c.value = values_of(vc.value);
    c.jacobian = values_of(vc.jacobian);
    ad::reset_op_tally();
    ref_y = ref_value();
    ref_value_ops = ad::op_tally().total();
    ad::reset_op_tally();
    ra = ref_analytical();
    ra.ops = ad::op_tally().total();
    ad::reset_op_tally();
    rc = ref_autodiff();
    rc.ops = ad::op_tally().total();
  }
  ARBOR_EXPECT_REL(y, ref_y, 0.0);
  ARBOR_EXPECT_REL(a.value, ra.value, 0.0);
  ARBOR_EXPECT_REL(a.jacobian, ra.jacobian, 0.0);
  ARBOR_EXPECT_REL(c.value, rc.value, 0.0);
  ARBOR_EXPECT_REL(c.jacobian, rc.jacobian, 0.0);
  ARBOR_EXPECT_REL(c.value, a.value, 1e-12);
  ARBOR_EXPECT_REL(c.jacobian, a.jacobian, 1e-9);
  EXPECT_GT(ref_value_ops, 0u);
  EXPECT_EQ(value_ops, ref_value_ops);
  EXPECT_EQ(a.ops, ra.ops);
  EXPECT_EQ(c.ops, rc.ops);
  EXPECT_NE(a.ops, c.ops);
}

Vec<2> dp_q() {
  return Vec<2>(0.3, -0.7);
}
Vec<2> dp_v() {
  return Vec<2>(0.5, -1.2);
}
Vec<2> dp_u() {
  return Vec<2>(0.4, -0.1);
}  // tau, or the acceleration for inverse dynamics
Vec<7> kinova_q() {
  Vec<7> q;
  q << 0.1, 0.4, -0.3, 1.2, 0.2, -0.5, 0.7;
  return q;
}

TEST(ExprCall, ForwardDynamicsProviders_DoublePendulum) {
  using R = DP;
  using F = ad::ForwardDynamics<R>;
  using D = ad::Dual<ad::Counted, 6>;
  constexpr ad::Symbol<0, 2> q;
  constexpr ad::Symbol<1, 2> v;
  constexpr ad::Symbol<2, 2> tau;
  const CVec<2> qc = counted_inputs<2>(dp_q()), vc = counted_inputs<2>(dp_v()),
                tc = counted_inputs<2>(dp_u());
  const auto qd = seeded<6, 2>(qc, 0), vd = seeded<6, 2>(vc, 2), td = seeded<6, 2>(tc, 4);
  auto dc = std::make_unique<arbor::Data<R, ad::Counted>>();
  auto gc = std::make_unique<arbor::DerivativeData<R, ad::Counted>>();
  auto dd = std::make_unique<arbor::Data<R, D>>();
  auto wa = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical, ad::Counted>>();
  auto wc = std::make_unique<ad::JacobianWorkspace<F, ad::AutoDiff, ad::Counted>>();
  check_providers<2, 6>(
      ad::call<ad::Analytical>(ad::bind<F>(*wa), q, v, tau),
      ad::call<ad::AutoDiff>(ad::bind<F>(*wc), q, v, tau),
      [&] { return values_of(arbor::aba<R>(*dc, qc, vc, tc)); },
      [&] {
        arbor::aba_derivatives<R>(*dc, *gc, qc, vc, tc);
        Measured<2, 6> r;
        r.value = values_of(dc->ddq);
        r.jacobian << values_of(gc->ddq_dq), values_of(gc->ddq_dv), values_of(dc->Minv);
        return r;
      },
      [&] { return from_duals<2, 6>(arbor::aba<R>(*dd, qd, vd, td)); }, qc, vc, tc);
}

TEST(ExprCall, SeededArgumentsScatterJacobianColumns) {
  // A call whose input is made of arguments directly takes J's columns without products (the
  // unit seeds are known at compile time); a parameter argument contributes no columns, and an
  // argument used twice gets the sum of its columns. Checked against the general chain rule
  // (an input that is an expression) and against aba_derivatives called directly.
  using R = DP;
  using F = ad::ForwardDynamics<R>;
  constexpr ad::Symbol<0, 2> a;
  constexpr ad::Symbol<1, 2> b;
  const CVec<2> qc = counted_inputs<2>(dp_q()), tc = counted_inputs<2>(dp_u());
  auto dc = std::make_unique<arbor::Data<R, ad::Counted>>();
  auto gc = std::make_unique<arbor::DerivativeData<R, ad::Counted>>();
  auto w = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical, ad::Counted>>();
  const auto f = ad::bind<F>(*w);
  Mat<2, 4> J_twice, J_general;
  Mat<2, 2> J_q_only;
  std::uint64_t ops_twice = 0, ops_q_only = 0, ops_ref = 0;
  Mat<2, 6> ref;
  {
    NoAllocScope guard;
    // ddq(q, v = q, tau): d/dq = ddq_dq + ddq_dv, d/dtau = Minv
    ad::reset_op_tally();
    J_twice = values_of(ad::jacobian(ad::call<ad::Analytical>(f, a, a, b), qc, tc));
    ops_twice = ad::op_tally().total();
    J_general = values_of(ad::jacobian(ad::call<ad::Analytical>(f, 1.0 * a, a, b), qc, tc));
    // with respect to a only (b is a parameter)
    ad::reset_op_tally();
    J_q_only = values_of(ad::jacobian<0>(ad::call<ad::Analytical>(f, a, a, b), qc, tc));
    ops_q_only = ad::op_tally().total();
    ad::reset_op_tally();
    arbor::aba_derivatives<R>(*dc, *gc, qc, qc, tc);
    ops_ref = ad::op_tally().total();
    ref << values_of(gc->ddq_dq), values_of(gc->ddq_dv), values_of(dc->Minv);
  }
  Mat<2, 4> expected;
  expected << ref.leftCols<2>() + ref.middleCols<2>(2), ref.rightCols<2>();
  ARBOR_EXPECT_REL(J_twice, expected, 1e-15);
  ARBOR_EXPECT_REL(J_general, expected, 1e-15);
  ARBOR_EXPECT_REL(J_q_only, expected.leftCols<2>().eval(), 1e-15);
  // the scatter adds one addition per entry of the summed columns (2 x 2), nothing else
  EXPECT_EQ(ops_twice, ops_ref + 4);
  EXPECT_EQ(ops_q_only, ops_ref + 4);
}

TEST(ExprCall, InverseDynamicsProviders_DoublePendulum) {
  using R = DP;
  using F = ad::InverseDynamics<R>;
  using D = ad::Dual<ad::Counted, 6>;
  constexpr ad::Symbol<0, 2> q;
  constexpr ad::Symbol<1, 2> v;
  constexpr ad::Symbol<2, 2> acc;
  const CVec<2> qc = counted_inputs<2>(dp_q()), vc = counted_inputs<2>(dp_v()),
                ac = counted_inputs<2>(dp_u());
  const auto qd = seeded<6, 2>(qc, 0), vd = seeded<6, 2>(vc, 2), add = seeded<6, 2>(ac, 4);
  auto dc = std::make_unique<arbor::Data<R, ad::Counted>>();
  auto gc = std::make_unique<arbor::DerivativeData<R, ad::Counted>>();
  auto dd = std::make_unique<arbor::Data<R, D>>();
  auto wa = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical, ad::Counted>>();
  auto wc = std::make_unique<ad::JacobianWorkspace<F, ad::AutoDiff, ad::Counted>>();
  check_providers<2, 6>(
      ad::call<ad::Analytical>(ad::bind<F>(*wa), q, v, acc),
      ad::call<ad::AutoDiff>(ad::bind<F>(*wc), q, v, acc),
      [&] { return values_of(arbor::rnea<R>(*dc, qc, vc, ac)); },
      [&] {
        arbor::rnea_derivatives<R>(*dc, *gc, qc, vc, ac);
        Measured<2, 6> r;
        r.value = values_of(dc->tau);
        r.jacobian << values_of(gc->dtau_dq), values_of(gc->dtau_dv), values_of(dc->M);
        return r;
      },
      [&] { return from_duals<2, 6>(arbor::rnea<R>(*dd, qd, vd, add)); }, qc, vc, ac);
}

TEST(ExprCall, FramePositionProviders_DoublePendulum) {
  using R = DP;
  constexpr int frame = DP::frame_id::link2;
  using F = ad::FramePosition<R, frame>;
  using D = ad::Dual<ad::Counted, 2>;
  constexpr ad::Symbol<0, 2> q;
  const CVec<2> qc = counted_inputs<2>(dp_q());
  const auto qd = seeded<2, 2>(qc, 0);
  auto dc = std::make_unique<arbor::Data<R, ad::Counted>>();
  auto dd = std::make_unique<arbor::Data<R, D>>();
  auto wa = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical, ad::Counted>>();
  auto wc = std::make_unique<ad::JacobianWorkspace<F, ad::AutoDiff, ad::Counted>>();
  check_providers<3, 2>(
      ad::call<ad::Analytical>(ad::bind<F>(*wa), q), ad::call<ad::AutoDiff>(ad::bind<F>(*wc), q),
      [&] {
        arbor::forward_kinematics<R>(*dc, qc);
        return values_of(arbor::frame_placement<R>(*dc, frame).p);
      },
      [&] {
        Eigen::Matrix<ad::Counted, 3, 2> J = Eigen::Matrix<ad::Counted, 3, 2>::Zero();
        arbor::compute_frame_position_derivative<R>(*dc, qc, frame, J);
        Measured<3, 2> r;
        r.value = values_of(dc->oMf[frame].p);
        r.jacobian = values_of(J);
        return r;
      },
      [&] {
        arbor::forward_kinematics<R>(*dd, qd);
        return from_duals<3, 2>(arbor::frame_placement<R>(*dd, frame).p);
      },
      qc);
}

TEST(ExprCall, FramePositionJacobianAtDouble_KinovaGen3) {
  // the double instantiation: both tags against compute_frame_position_derivative
  using R = Kinova;
  constexpr int frame = Kinova::frame_id::end_effector_link;
  using F = ad::FramePosition<R, frame>;
  constexpr ad::Symbol<0, 7> q;
  const Vec<7> qv = kinova_q();
  auto d = std::make_unique<arbor::Data<R, double>>();
  auto wa = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical>>();
  auto wc = std::make_unique<ad::JacobianWorkspace<F, ad::AutoDiff>>();
  const auto fa = ad::bind<F>(*wa);
  const auto fc = ad::bind<F>(*wc);
  ad::ValueJacobian<double, 3, 7> a, c;
  Mat<3, 7> J = Mat<3, 7>::Zero();
  Vec<3> y;
  {
    NoAllocScope guard;
    y = ad::evaluate(ad::call<ad::Analytical>(fa, q), qv);
    a = ad::value_and_jacobian(ad::call<ad::Analytical>(fa, q), qv);
    c = ad::value_and_jacobian(ad::call<ad::AutoDiff>(fc, q), qv);
    arbor::compute_frame_position_derivative<R>(*d, qv, frame, J);
  }
  const Vec<3> p = d->oMf[frame].p;
  ARBOR_EXPECT_REL(y, p, 1e-15);
  ARBOR_EXPECT_REL(a.value, p, 0.0);
  ARBOR_EXPECT_REL(a.jacobian, J, 0.0);
  ARBOR_EXPECT_REL(c.value, p, 1e-15);
  ARBOR_EXPECT_REL(c.jacobian, a.jacobian, 1e-9);
}

TEST(ExprCall, ChainRuleThroughTheNode) {
  // p(0.5 q + q0): d/dq = 0.5 J(0.5 q + q0), J from the analytical routine called directly
  using R = Kinova;
  constexpr int frame = Kinova::frame_id::end_effector_link;
  using F = ad::FramePosition<R, frame>;
  constexpr ad::Symbol<0, 7> q;
  const Vec<7> qv = kinova_q();
  Vec<7> q0;
  q0 << 0.2, -0.1, 0.3, 0.05, -0.4, 0.6, 0.1;
  auto d = std::make_unique<arbor::Data<R, double>>();
  auto wa = std::make_unique<ad::JacobianWorkspace<F, ad::Analytical>>();
  auto wc = std::make_unique<ad::JacobianWorkspace<F, ad::AutoDiff>>();
  Mat<3, 7> Ja, Jc, J = Mat<3, 7>::Zero();
  {
    NoAllocScope guard;
    Ja = ad::jacobian(ad::call<ad::Analytical>(ad::bind<F>(*wa), 0.5 * q + ad::constant(q0)), qv);
    Jc = ad::jacobian(ad::call<ad::AutoDiff>(ad::bind<F>(*wc), 0.5 * q + ad::constant(q0)), qv);
    arbor::compute_frame_position_derivative<R>(*d, (0.5 * qv + q0).eval(), frame, J);
  }
  ARBOR_EXPECT_REL(Ja, (0.5 * J).eval(), 1e-15);
  ARBOR_EXPECT_REL(Jc, (0.5 * J).eval(), 1e-9);
}

// ---- (c) a path error with a custom node: Kinova end effector against a helix -------------------

constexpr int kEe = Kinova::frame_id::end_effector_link;
constexpr double kRadius = 0.2;
constexpr double kPitch = 0.1;

Vec<3> helix_centre() {
  return Vec<3>(0.3, 0.1, 0.6);
}

/// p_ref(s) = c + (r cos s, r sin s, a s), plain double.
Vec<3> helix(double s) {
  return helix_centre() + Vec<3>(kRadius * std::cos(s), kRadius * std::sin(s), kPitch * s);
}

using EeFunction = ad::FramePosition<Kinova, kEe>;
/// What path_cost<Tag> needs: gradients at double (the node at double) and Hessians over the 8
/// directions (q, s) (the node at Dual<double, 8>).
template <class Tag>
using PathWorkspace =
    ad::MergedWorkspace<ad::JacobianWorkspace<EeFunction, Tag, double>,
                        ad::JacobianWorkspace<EeFunction, Tag, ad::Dual<double, 8>>>;

/// |p_ee(q) - p_ref(s)|^2 as an expression, Jacobian of the node from provider Tag, on ws.
template <class Tag>
auto path_cost(PathWorkspace<Tag>& ws) {
  constexpr ad::Symbol<0, 7> q;
  constexpr ad::Symbol<1, 1> s;
  const auto p_ref = ad::constant(helix_centre()) +
                     ad::cat(kRadius * ad::cos(s), kRadius * ad::sin(s), kPitch * s);
  const auto e = ad::call<Tag>(ad::bind<EeFunction>(ws), q) - p_ref;
  return ad::squared_norm(e);
}

class ExprPathError : public ::testing::Test {
 protected:
  void SetUp() override {
    q0 << 0.1, 0.4, -0.3, 1.2, 0.2, -0.5, 0.7;
    z0 << q0, s0;
  }
  /// The cost from forward kinematics in plain double.
  double cost(const Vec<8>& z) {
    arbor::forward_kinematics<Kinova>(*d, z.head<7>());
    const Vec<3> p = arbor::frame_placement<Kinova>(*d, kEe).p;
    return (p - helix(z[7])).squaredNorm();
  }
  template <class Tag>
  void check() {
    auto ws = std::make_unique<PathWorkspace<Tag>>();
    const auto f = path_cost<Tag>(*ws);
    ad::ValueGradientHessian<double, 8> r;
    ARBOR_EXPECT_NO_ALLOC(r = ad::value_gradient_hessian(f, q0, s0));
    // value, and gradient by hand: 2 J^T e (J from the analytical routine), -2 e^T p_ref'(s)
    Mat<3, 7> J = Mat<3, 7>::Zero();
    Vec<8> g_hand, g_fd;
    Mat<8> H_fd;
    double c0 = 0;
    Vec<3> e;
    const Vec<3> dp_ref(-kRadius * std::sin(s0), kRadius * std::cos(s0), kPitch);
    const Vec<3> ddp_ref(-kRadius * std::cos(s0), -kRadius * std::sin(s0), 0.0);
    {
      NoAllocScope guard;
      c0 = cost(z0);
      arbor::compute_frame_position_derivative<Kinova>(*d, q0, kEe, J);
      e = d->oMf[kEe].p - helix(s0);
      g_hand << 2 * J.transpose() * e, -2 * e.dot(dp_ref);
      // central differences: the double cost for the gradient, the ET gradient for the Hessian
      const double h = 1e-5;
      for (int k = 0; k < 8; ++k) {
        Vec<8> zp = z0, zm = z0;
        zp[k] += h;
        zm[k] -= h;
        g_fd[k] = (cost(zp) - cost(zm)) / (2 * h);
        const Vec<8> gp = ad::gradient(f, zp.head<7>().eval(), zp[7]);
        const Vec<8> gm = ad::gradient(f, zm.head<7>().eval(), zm[7]);
        H_fd.col(k) = (gp - gm) / (2 * h);
      }
    }
    EXPECT_NEAR(r.value, c0, 1e-14);
    ARBOR_EXPECT_REL(r.gradient, g_hand, 1e-12);
    ARBOR_EXPECT_REL(r.gradient, g_fd, 1e-8);
    ARBOR_EXPECT_REL(r.hessian, H_fd, 1e-7);
    EXPECT_LE(asymmetry(r.hessian), 1e-12);
    // the s-s entry by hand: 2 |p_ref'|^2 - 2 e^T p_ref''
    EXPECT_NEAR(r.hessian(7, 7), 2 * dp_ref.squaredNorm() - 2 * e.dot(ddp_ref), 1e-12);
    // the q-q block's Gauss-Newton part is 2 J^T J; the rest is 2 sum_i e_i d2 p_i / dq2, so
    // the q-s block is exactly -2 J^T p_ref'(s)
    ARBOR_EXPECT_REL((r.hessian.block<7, 1>(0, 7)), (-2 * J.transpose() * dp_ref).eval(), 1e-12);
  }

  std::unique_ptr<arbor::Data<Kinova, double>> d = std::make_unique<arbor::Data<Kinova, double>>();
  Vec<7> q0;
  double s0 = 0.4;
  Vec<8> z0;
};

TEST_F(ExprPathError, Analytical) {
  check<ad::Analytical>();
}
TEST_F(ExprPathError, AutoDiff) {
  check<ad::AutoDiff>();
}

TEST_F(ExprPathError, ProvidersAgree) {
  auto wa = std::make_unique<PathWorkspace<ad::Analytical>>();
  auto wc = std::make_unique<PathWorkspace<ad::AutoDiff>>();
  ad::ValueGradientHessian<double, 8> a, c;
  {
    NoAllocScope guard;
    a = ad::value_gradient_hessian(path_cost<ad::Analytical>(*wa), q0, s0);
    c = ad::value_gradient_hessian(path_cost<ad::AutoDiff>(*wc), q0, s0);
  }
  EXPECT_NEAR(a.value, c.value, 1e-14);
  ARBOR_EXPECT_REL(a.gradient, c.gradient, 1e-9);
  ARBOR_EXPECT_REL(a.hessian, c.hessian, 1e-9);
}

}  // namespace
