// User functions with generated Jacobians (arbor/ad/user_function.hpp; the code generated at
// build time by arbor_add_function_ad from tests/ad/user_functions_example.hpp). Expected values
// are independent of the generated code: closed-form derivatives written out here, dual numbers
// through the same eval (AutoDiff), central finite differences, and operation counts by hand.
// Every library call runs under the allocation guard.
#include <gtest/gtest.h>

#include <arbor/ad/expr.hpp>
#include <arbor/ad/user_function.hpp>
#include <cmath>
#include <cstdint>
#include <user_functions_example_ad.hpp>

#include "alloc_guard.hpp"
#include "op_tick.hpp"

namespace {

namespace ad = arbor::ad;
using arbor::test::NoAllocScope;
using arbor_test::Norm2;
using arbor_test::ScaledProduct;
using arbor_test::TwoOutputs;

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int M, int N = M>
using Mat = Eigen::Matrix<double, M, N>;

/// Closed-form Jacobian of TwoOutputs.
Mat<2, 3> two_outputs_jacobian(const Vec<3>& x, const double* p) {
  const double d = p[1] + x[1] * x[1];
  Mat<2, 3> J;
  J << p[0] * x[1], p[0] * x[0], std::cos(x[2]), 2 * x[0] / d, -x[0] * x[0] * 2 * x[1] / (d * d),
      0.0;
  return J;
}

TEST(UserFunction, GeneratedJacobianEqualsClosedFormAndAutoDiff) {
  static_assert(ad::GeneratedFunction<TwoOutputs>::available);
  const double params[2] = {1.7, 0.4};
  const auto f = ad::user_function<TwoOutputs>(params);
  for (int trial = 0; trial < 5; ++trial) {
    const Vec<3> x(0.3 - 0.4 * trial, 1.1 + 0.2 * trial, -0.8 + 0.5 * trial);
    Vec<2> yg, ya, yv;
    Mat<2, 3> Jg, Ja;
    {
      NoAllocScope guard;
      f.value_and_jacobian<ad::Generated>(x, yg, Jg);
      f.value_and_jacobian<ad::AutoDiff>(x, ya, Ja);
      f.value(x, yv);
    }
    const Vec<2> y(params[0] * x[0] * x[1] + std::sin(x[2]),
                   x[0] * x[0] / (params[1] + x[1] * x[1]));
    EXPECT_LE((yg - y).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LE((yv - y).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LE((Jg - two_outputs_jacobian(x, params)).cwiseAbs().maxCoeff(), 1e-13);
    EXPECT_LE((Jg - Ja).cwiseAbs().maxCoeff(), 1e-14);
  }
}

TEST(UserFunction, ParametersAreReadAtEveryEvaluation) {
  double params[2] = {1.0, 1.0};
  const auto f = ad::user_function<TwoOutputs>(params);
  const Vec<3> x(0.5, -0.25, 0.75);
  Vec<2> y1, y2;
  Mat<2, 3> J1, J2;
  f.value_and_jacobian<ad::Generated>(x, y1, J1);
  params[0] = -2.0;  // the handle points at them: the next evaluation sees the change
  params[1] = 3.0;
  f.value_and_jacobian<ad::Generated>(x, y2, J2);
  const double first[2] = {1.0, 1.0};
  EXPECT_LE((J1 - two_outputs_jacobian(x, first)).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LE((J2 - two_outputs_jacobian(x, params)).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(UserFunction, NoParameters) {
  const auto f = ad::user_function<Norm2>();
  const Vec<2> x(3.0, -4.0);
  Vec<1> y;
  Mat<1, 2> J;
  {
    NoAllocScope guard;
    f.value_and_jacobian<ad::Generated>(x, y, J);
  }
  EXPECT_DOUBLE_EQ(y[0], 5.0);
  EXPECT_DOUBLE_EQ(J(0, 0), 0.6);
  EXPECT_DOUBLE_EQ(J(0, 1), -0.8);
}

TEST(UserFunction, InExpressionsJacobianAndHessian) {
  // e = TwoOutputs(x0, x1, u0) . [1, 1]: its gradient and Hessian in (x, u), the generated
  // Jacobian run at dual numbers for the Hessian, against central differences of the
  // closed-form gradient
  constexpr ad::Symbol<0, 2> xs;
  constexpr ad::Symbol<1, 1> us;
  const double params[2] = {0.9, 0.6};
  const auto node = ad::call<ad::Generated>(ad::user_function<TwoOutputs>(params), xs, us);
  const auto node_ad = ad::call<ad::AutoDiff>(ad::user_function<TwoOutputs>(params), xs, us);
  const auto e = ad::sum(node);
  const Vec<2> x(0.7, -0.3);
  const double u = 0.4;
  ad::ValueJacobian<double, 2, 3> vj, vj_ad;
  ad::ValueGradientHessian<double, 3> vgh;
  {
    NoAllocScope guard;
    vj = ad::value_and_jacobian(node, x, u);
    vj_ad = ad::value_and_jacobian(node_ad, x, u);
    vgh = ad::value_gradient_hessian(e, x, u);
  }
  const Vec<3> z(x[0], x[1], u);
  EXPECT_LE((vj.jacobian - two_outputs_jacobian(z, params)).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LE((vj.jacobian - vj_ad.jacobian).cwiseAbs().maxCoeff(), 1e-14);
  auto grad = [&](const Vec<3>& w) {
    const Mat<2, 3> J = two_outputs_jacobian(w, params);
    return Vec<3>(J.colwise().sum().transpose());
  };
  EXPECT_LE((vgh.gradient - grad(z)).cwiseAbs().maxCoeff(), 1e-14);
  Mat<3> H;
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Vec<3> zp = z, zm = z;
    zp[k] += h;
    zm[k] -= h;
    H.col(k) = (grad(zp) - grad(zm)) / (2 * h);
  }
  EXPECT_LE((vgh.hessian - H).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_LE((vgh.hessian - vgh.hessian.transpose()).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(UserFunction, GeneratedCodeExecutesItsLiveOperations) {
  // y = (x0 x1) p0: value t = x0 x1, y = t p0 (2 multiplications); Jacobian [x1 p0, x0 p0]
  // (2 more, whichever mode: p0 x1 and p0 x0). Forward mode at Dual<Tick, 2> through eval:
  // t = x0 x1 is 1 + 2 x 3 = 7, t p0 (p0 a constant dual) 7 as well: 14.
  using ad::Tick;
  static_assert(ad::GeneratedFunction<ScaledProduct>::jacobian_ops == 4);
  const Tick p[1] = {Tick(1.5)};
  const Tick x[2] = {Tick(0.5), Tick(-2.0)};
  Tick y[1], J[2];
  ad::reset_tick_count();
  ad::GeneratedFunction<ScaledProduct>::jacobian(x, p, y, J);
  EXPECT_EQ(ad::tick_count(), 4u);
  EXPECT_DOUBLE_EQ(y[0].x, -1.5);
  EXPECT_DOUBLE_EQ(J[0].x, -3.0);
  EXPECT_DOUBLE_EQ(J[1].x, 0.75);
  const double pd[1] = {1.5};
  const auto f = ad::user_function<ScaledProduct>(pd);
  Eigen::Matrix<Tick, 2, 1> xv(x[0], x[1]);
  Eigen::Matrix<Tick, 1, 1> yv;
  Eigen::Matrix<Tick, 1, 2> Jv;
  ad::reset_tick_count();
  f.value_and_jacobian<ad::AutoDiff>(xv, yv, Jv);
  EXPECT_EQ(ad::tick_count(), 14u);
  EXPECT_DOUBLE_EQ(Jv(0, 0).x, -3.0);
}

TEST(UserFunction, CallNodeChainRuleSkipsStructuralZeros) {
  // node = TwoOutputs(sin(x0), x1, sin(u0)) in a Jacobian w.r.t. (x (3), u (2)): n = 5.
  // Operations at Tick, by hand:
  //   sin(x0), sin(u0) at Dual<Tick, 5>: sin and cos of the value, 5 products each      14
  //   the generated value and Jacobian (GeneratedFunction<TwoOutputs>::jacobian_ops)     17
  //   chain rule of the general columns 0 (sin(x0): direction 0 only) and 2 (sin(u0):
  //   direction 3 only), each entry a product and a sum, skipping J(1, 2) (y1 does not
  //   depend on x2): per kept direction 2 x 2 + 1 x 2 = 6, 2 directions                    12
  //   the seeded column 1 (x1) scattered: one sum per row                                  2
  // 45 in all; over every direction and entry (dense) the chain rule alone would be 40.
  using ad::Tick;
  static_assert(ad::GeneratedFunction<TwoOutputs>::jacobian_ops == 17);
  static_assert(!ad::GeneratedFunction<TwoOutputs>::nonzero[2 * 2 + 1]);  // J(1, 2)
  constexpr ad::Symbol<0, 3> xs;
  constexpr ad::Symbol<1, 2> us;
  const Tick params[2] = {Tick(0.8), Tick(1.3)};
  const auto node =
      ad::call<ad::Generated>(ad::user_function<TwoOutputs>(params), ad::sin(ad::element<0>(xs)),
                              ad::element<1>(xs), ad::sin(ad::element<0>(us)));
  Eigen::Matrix<Tick, 3, 1> x(Tick(0.4), Tick(-0.9), Tick(2.0));
  Eigen::Matrix<Tick, 2, 1> u(Tick(0.3), Tick(0.1));
  ad::ValueJacobian<Tick, 2, 5> vj;
  ad::reset_tick_count();
  vj = ad::value_and_jacobian(node, x, u);
  EXPECT_EQ(ad::tick_count(), 45u);
  // and the values: J = dTwoOutputs/dz diag(cos x0, 1, cos u0) on columns (x0, x1, u0)
  const double p[2] = {0.8, 1.3};
  const Vec<3> z(std::sin(0.4), -0.9, std::sin(0.3));
  const Mat<2, 3> Jz = two_outputs_jacobian(z, p);
  Mat<2, 5> J = Mat<2, 5>::Zero();
  J.col(0) = Jz.col(0) * std::cos(0.4);
  J.col(1) = Jz.col(1);
  J.col(3) = Jz.col(2) * std::cos(0.3);
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 5; ++k)
      EXPECT_NEAR(vj.jacobian(i, k).x, J(i, k), 1e-14) << i << ", " << k;
}

}  // namespace
