// The pendulum swing-up (problems.hpp) against IPOPT on the same discretised NLP (plain code,
// plain_ocp.hpp): SCQP (Gauss-Newton) and exact-Hessian SQP converge to IPOPT's solution in
// objective, trajectories and multipliers, and the NLP's KKT residuals of the controller's
// solution, recomputed from the plain functions by finite differences, are below tolerance.
//
// Setting: N = 60 intervals of h = 0.05 s (3 s), M = 2 RK4 steps, |torque| <= 3 (a third of
// m g l: the swing-up needs two swings), from hanging at rest; guess: hanging at rest, zero torque
// (the same for both solvers).
#include <gtest/gtest.h>

#include <memory>

#include "plain_ocp.hpp"
#include "problems.hpp"
#include "status_names.hpp"

namespace arbor::nmpc {
using ::arbor::test::status_names::operator<<;
}

namespace {
using namespace nmpc_test;
using arbor::ocp::HessianKind;

constexpr int N = 60, M = 2;
constexpr double w_terminal = 100.0;

PlainOcp plain_pendulum() {
  using P = PendulumData;
  PlainOcp o;
  o.nx = 2;
  o.nu = 1;
  o.N = N;
  o.F = [](const VecX& x, const VecX& u) {
    return VecX(rk4_plain([](const Eigen::Vector2d& y, double t) { return pendulum_ode(y, t); },
                          Eigen::Vector2d(x), u[0], P::h, M));
  };
  o.stage_cost = [](const VecX& x, const VecX& u) {
    return (x[0] - M_PI) * (x[0] - M_PI) + 0.1 * x[1] * x[1] + 0.01 * u[0] * u[0];
  };
  o.terminal_cost = [](const VecX& x) {
    return w_terminal * ((x[0] - M_PI) * (x[0] - M_PI) + x[1] * x[1]);
  };
  o.lbx = VecX::Constant(2, -std::numeric_limits<double>::infinity());
  o.ubx = -o.lbx;
  o.lbu = VecX::Constant(1, -P::u_max);
  o.ubu = VecX::Constant(1, P::u_max);
  o.x0 = VecX::Zero(2);
  return o;
}

const arbor::test::IpoptResult& ipopt_solution() {
  static const arbor::test::IpoptResult r = [] {
    const PlainOcp o = plain_pendulum();
    return solve_ipopt("pendulum", o, constant_guess(o));
  }();
  return r;
}

template <HessianKind H>
void check(const char* name, int max_iter, const Tolerances& tol) {
  const PlainOcp o = plain_pendulum();
  const auto problem = pendulum_problem<N, M>(w_terminal);
  using Ctrl = arbor::nmpc::Nmpc<std::remove_cvref_t<decltype(problem)>, double, H>;
  const auto ctrl = std::make_unique<Ctrl>(problem);
  const auto run = solve_nmpc(*ctrl, o, constant_guess(o), max_iter);
  expect_matches_ipopt(name, o, run, ipopt_solution(), tol);
}

TEST(IpoptPendulum, GaussNewton) {
  check<HessianKind::gauss_newton>("pendulum gauss_newton", 500, Tolerances{});
}

TEST(IpoptPendulum, ExactHessian) {
  check<HessianKind::exact>("pendulum exact", 100, Tolerances{});
}

}  // namespace
