// Linear dynamics, quadratic cost, no active inequality: the NMPC's solution (SCQP and exact-
// Hessian SQP) equals the finite-horizon LQR solution computed by a plain Riccati recursion
// (support/lqr_reference.hpp, dynamic Eigen), and the Riccati and the dense condensed QP agree.
// The OCP is a discretised mass-spring-damper with a second, coupled mass (nx = 4, nu = 2),
// written with the expression layer; the LQR data are written out from the same numbers
// (coupled_masses.hpp).
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
#include "coupled_masses.hpp"
#include "lqr_reference.hpp"
#include "status_names.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}

namespace {
namespace ad = arbor::ad;
namespace ocp = arbor::ocp;
using arbor::nmpc::NmpcStatus;

using namespace arbor::test::coupled_masses;

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
