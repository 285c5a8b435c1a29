// The 2-DoF arm (arm.hpp: examples/robots/double_pendulum.urdf, torque bounds, an end-effector
// wall) against IPOPT on the same discretised NLP, the plain one built on the independent textbook
// RBD: SCQP (Gauss-Newton) with the Analytical and with the AutoDiff provider each converges to
// IPOPT's solution (objective, trajectories, multipliers of the dynamics, the bounds and the wall),
// the NLP's KKT residuals of the controller's solution, recomputed from the plain functions, are
// below tolerance, and the two providers give the same solution.
//
// Setting: N = 30 intervals of h = 0.05 s (1.5 s), M = 2 RK4 steps, from hanging at rest; guess:
// hanging at rest, zero torque (the same for every solver).
#include <gtest/gtest.h>

#include <memory>

#include "arm.hpp"
#include "plain_ocp.hpp"
#include "status_names.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}

namespace {
using namespace nmpc_test;
using arbor::ocp::HessianKind;

constexpr int N = 30, M = 2;
constexpr double w_terminal = 100.0;

PlainOcp plain() {
  return plain_arm(N, M, w_terminal, Eigen::Vector4d(M_PI, 0, 0, 0));
}

const arbor::test::IpoptResult& ipopt_solution() {
  static const arbor::test::IpoptResult r = [] {
    const PlainOcp o = plain();
    return solve_ipopt("arm", o, constant_guess(o));
  }();
  return r;
}

/// Solves with provider Tag and Hessian H, compares with IPOPT, returns the solution.
template <class Tag, HessianKind H>
NlpPoint check(const char* name, int max_iter, const Tolerances& tol) {
  const PlainOcp o = plain();
  using W = ArmWorkspace<Tag, H == HessianKind::exact>;
  const auto ws = std::make_unique<W>();
  const auto problem = arm_problem<N, M, Tag>(*ws, w_terminal);
  using Ctrl = arbor::nmpc::Nmpc<std::remove_cvref_t<decltype(problem)>, double, H>;
  const auto ctrl = std::make_unique<Ctrl>(problem);
  const auto run = solve_nmpc(*ctrl, o, constant_guess(o), max_iter);
  expect_matches_ipopt(name, o, run, ipopt_solution(), tol);
  return run.point;
}

TEST(IpoptArm, GaussNewtonProvidersAgree) {
  const NlpPoint a = check<arbor::ad::Analytical, HessianKind::gauss_newton>(
      "arm gauss_newton analytical", 500, Tolerances{});
  const NlpPoint c = check<arbor::ad::AutoDiff, HessianKind::gauss_newton>(
      "arm gauss_newton autodiff", 500, Tolerances{});
  const double dw = (a.w - c.w).cwiseAbs().maxCoeff();
  const double dl =
      std::max((a.lambda - c.lambda).cwiseAbs().maxCoeff(), (a.z - c.z).cwiseAbs().maxCoeff());
  std::printf("[nmpc-ipopt] arm: Analytical vs AutoDiff: max |dw| %.2e, max |dlambda| %.2e\n", dw,
              dl);
  EXPECT_LE(dw, 1e-9);
  EXPECT_LE(dl, 1e-7);
}

}  // namespace
