// The cart-pole swing-up (cartpole.hpp) against IPOPT on the same discretised NLP (plain code):
// SCQP (Gauss-Newton) and exact-Hessian SQP converge to IPOPT's solution in objective,
// trajectories and multipliers (force bounds and cart-position bounds active), and the NLP's KKT
// residuals of the controller's solution, recomputed from the plain functions by finite
// differences, are below tolerance.
//
// Setting: N = 50 intervals of h = 0.05 s (2.5 s), M = 2 RK4 steps, |f| <= 8, |p| <= 0.6, from
// hanging at rest; guess: hanging at rest, zero force (the same for both solvers).
#include <gtest/gtest.h>

#include <memory>

#include "cartpole.hpp"
#include "plain_ocp.hpp"
#include "status_names.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}

namespace {
using namespace nmpc_test;
using arbor::ocp::HessianKind;

constexpr int N = 50, M = 2;
constexpr double w_terminal = 100.0;

PlainOcp plain() {
  return plain_cartpole(N, M, w_terminal, Eigen::Vector4d::Zero());
}

const arbor::test::IpoptResult& ipopt_solution() {
  static const arbor::test::IpoptResult r = [] {
    const PlainOcp o = plain();
    return solve_ipopt("cart-pole", o, constant_guess(o));
  }();
  return r;
}

template <HessianKind H>
using Ctrl = arbor::nmpc::Nmpc<decltype(cartpole_problem<N, M>()), double, H>;

template <HessianKind H>
NmpcRun<Ctrl<H>> run(const VecX& w0, int max_iter) {
  const auto ctrl = std::make_unique<Ctrl<H>>(cartpole_problem<N, M>(w_terminal));
  return solve_nmpc(*ctrl, plain(), w0, max_iter);
}

TEST(IpoptCartPole, GaussNewton) {
  const PlainOcp o = plain();
  expect_matches_ipopt("cart-pole gauss_newton", o,
                       run<HessianKind::gauss_newton>(constant_guess(o), 500), ipopt_solution(),
                       Tolerances{});
}

// Exact-Hessian SQP from the cold guess does not converge on this problem (100 iterations end
// near, not at, a stationary point: objective 656.76 against 652.15; recorded by
// ExactHessianColdStart), so it starts from the plan of 20 SCQP iterations (multipliers reset):
// the usual Gauss-Newton-then-Newton sequence.
TEST(IpoptCartPole, ExactHessianFromScqpPlan) {
  const PlainOcp o = plain();
  const auto warm = run<HessianKind::gauss_newton>(constant_guess(o), 20);
  EXPECT_EQ(warm.status, arbor::nmpc::NmpcStatus::iteration_limit);
  expect_matches_ipopt("cart-pole exact (from 20 SCQP iterations)", o,
                       run<HessianKind::exact>(warm.point.w, 100), ipopt_solution(), Tolerances{});
}

// Records (no assertion) where exact-Hessian SQP from the cold guess ends.
TEST(IpoptCartPole, ExactHessianColdStart) {
  const PlainOcp o = plain();
  const auto r = run<HessianKind::exact>(constant_guess(o), 100);
  const Kkt kkt = kkt_residuals(o, r.point);
  std::printf(
      "[nmpc-ipopt] cart-pole exact from the cold guess: %s after %d iterations, objective "
      "%.10g (IPOPT %.10g), stationarity %.2e\n",
      to_string(r.status), r.info.iterations, o.objective(r.point.w), ipopt_solution().objective,
      kkt.stationarity);
}

}  // namespace
