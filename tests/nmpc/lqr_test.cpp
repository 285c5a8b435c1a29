// Linear dynamics, quadratic cost, no active inequality: the NMPC's solution (SCQP and exact-
// Hessian SQP) equals the finite-horizon LQR solution computed by a plain Riccati recursion
// (support/lqr_reference.hpp, dynamic Eigen), and the Riccati and the dense condensed QP agree.
// The OCP is a discretised mass-spring-damper with a second, coupled mass (nx = 4, nu = 2),
// written with the expression layer; the LQR data are written out here from the same numbers.
#if defined(__GNUC__) && !defined(__clang__)
// GCC 12 at -O3 reports a use-after-free inside Eigen's aligned_free, inlined from the dynamic
// matrices of lqr_reference.hpp (a known false positive of that warning)
#pragma GCC diagnostic ignored "-Wuse-after-free"
#endif
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>

#include "alloc_guard.hpp"
#include "arbor/ad/expr.hpp"
#include "arbor/nmpc/controller.hpp"
#include "lqr_reference.hpp"
#include "status_names.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}

namespace {
namespace ad = arbor::ad;
namespace ocp = arbor::ocp;
using arbor::nmpc::NmpcStatus;

constexpr int N = 20;
constexpr double h = 0.1, k1 = 2.0, k2 = 1.0, c = 0.3;  // step, springs, damping
// x = [p1, p2, v1, v2], u = [f1, f2]; explicit Euler of two coupled masses (a linear map)
constexpr double A[4][4] = {{1, 0, h, 0},
                            {0, 1, 0, h},
                            {-h * (k1 + k2), h* k2, 1 - h* c, 0},
                            {h * k2, -h* k2, 0, 1 - h* c}};
constexpr double B[4][2] = {{0, 0}, {0, 0}, {h, 0}, {0, h}};
constexpr std::array<double, 4> wx{1.0, 2.0, 0.1, 0.1};  // stage weights (sum w x^2)
constexpr std::array<double, 2> wu{0.05, 0.02};
constexpr double wN = 5.0;

auto linear_problem() {
  using D = ocp::Dims<4, 2, 1, N>;
  const auto x = D::x;
  const auto u = D::u;
  auto row = [&](auto i) {
    constexpr int r = decltype(i)::value;
    return A[r][0] * ad::element<0>(x) + A[r][1] * ad::element<1>(x) + A[r][2] * ad::element<2>(x) +
           A[r][3] * ad::element<3>(x) + B[r][0] * ad::element<0>(u) + B[r][1] * ad::element<1>(u);
  };
  const auto F =
      ad::cat(row(std::integral_constant<int, 0>{}), row(std::integral_constant<int, 1>{}),
              row(std::integral_constant<int, 2>{}), row(std::integral_constant<int, 3>{}));
  return ocp::make_problem<D>(F,
                              ocp::path_costs(ocp::least_squares(x, wx), ocp::least_squares(u, wu)),
                              ocp::terminal_costs(ocp::least_squares(x, wN)));
}

arbor::test::LqrProblem lqr_data(const Eigen::Vector4d& x0) {
  arbor::test::LqrProblem p;
  p.N = N;
  Eigen::MatrixXd a(4, 4), b(4, 2);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j)
      a(i, j) = A[i][j];
    for (int j = 0; j < 2; ++j)
      b(i, j) = B[i][j];
  }
  p.A = {a};
  p.B = {b};
  // sum w_i x_i^2 = 1/2 x' (2 W) x
  p.Q = {Eigen::MatrixXd(2.0 * Eigen::Vector4d(wx[0], wx[1], wx[2], wx[3]).asDiagonal())};
  p.R = {Eigen::MatrixXd(2.0 * Eigen::Vector2d(wu[0], wu[1]).asDiagonal())};
  p.P_N = 2.0 * wN * Eigen::MatrixXd::Identity(4, 4);
  p.x0 = x0;
  return p;
}

template <arbor::ocp::HessianKind H>
void check_against_lqr() {
  const auto problem = linear_problem();
  using Ctrl = arbor::nmpc::Nmpc<decltype(problem), double, H>;
  static Ctrl ctrl(problem);
  const Eigen::Vector4d x0(0.5, -0.3, 0.2, 0.1);
  // tolerances 1e-10 (NLP and QP), so that the comparison measures the method, not the stopping
  // test (at the default 1e-8 the QP stops with errors of 1e-8 in x and 2e-7 in the costates)
  auto& s = ctrl.settings();
  s.tol_stationarity = s.tol_primal = s.tol_complementarity = 1e-10;
  s.qp.tol_primal = s.qp.tol_dual = s.qp.tol_comp = 1e-10;
  ASSERT_EQ(ctrl.set_initial_guess(Eigen::Vector4d::Zero(), Eigen::Vector2d::Zero()),
            NmpcStatus::accepted);
  NmpcStatus st;
  {
    arbor::test::NoAllocScope guard;
    st = ctrl.solve(x0);
  }
  ASSERT_EQ(st, NmpcStatus::converged);
  // one Newton step solves a linear-quadratic problem (the QP stops at its 1e-10 tolerances)
  EXPECT_EQ(ctrl.info().iterations, 1);

  const auto lqr = arbor::test::lqr_riccati(lqr_data(x0));
  const auto dense = arbor::test::lqr_dense_qp(lqr_data(x0));
  for (int k = 0; k <= N; ++k) {
    EXPECT_LT((ctrl.state(k) - lqr.x[std::size_t(k)]).cwiseAbs().maxCoeff(), 1e-9) << "x_" << k;
    EXPECT_LT((lqr.x[std::size_t(k)] - dense.x[std::size_t(k)]).cwiseAbs().maxCoeff(), 1e-10);
  }
  for (int k = 0; k < N; ++k)
    EXPECT_LT((ctrl.input(k) - lqr.u[std::size_t(k)]).cwiseAbs().maxCoeff(), 1e-9) << "u_" << k;
  // the control law: u_0 = K_0 x0 + k_0 from the Riccati gains
  const Eigen::VectorXd u0 = lqr.K[0] * x0 + lqr.k[0];
  EXPECT_LT((ctrl.control() - u0).cwiseAbs().maxCoeff(), 1e-9);
  // costates: the multiplier of x_{k+1} - F = 0 is -(P_{k+1} x_{k+1} + p_{k+1})
  for (int k = 0; k < N; ++k) {
    const Eigen::VectorXd lam =
        -(lqr.P[std::size_t(k + 1)] * lqr.x[std::size_t(k + 1)] + lqr.p[std::size_t(k + 1)]);
    EXPECT_LT((ctrl.dynamics_multiplier(k) - lam).cwiseAbs().maxCoeff(), 1e-8) << "lambda_" << k;
  }
}

TEST(NmpcLqr, GaussNewtonEqualsRiccati) {
  check_against_lqr<arbor::ocp::HessianKind::gauss_newton>();
}
TEST(NmpcLqr, ExactHessianEqualsRiccati) {
  check_against_lqr<arbor::ocp::HessianKind::exact>();
}

}  // namespace
