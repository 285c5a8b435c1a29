// The 2-DoF arm (arm.hpp) with exact-Hessian SQP against IPOPT (see ipopt_arm_test.cpp for the
// setting): the Lagrangian's Hessian runs the RBD call nodes at nested duals (Analytical: the
// analytical first-order routines at Dual<double, 6>; AutoDiff: Dual<Dual<double, 6>, 6> through
// the RBD templates). One provider per translation unit (compile memory): this file is built
// twice, with ARM_EXACT_AUTODIFF defined for AutoDiff; each converges to IPOPT's solution, so
// the two agree through it (to the tolerances below).
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

#if defined(ARM_EXACT_AUTODIFF)
using Tag = arbor::ad::AutoDiff;
constexpr const char* kName = "arm exact autodiff (from 20 SCQP iterations)";
#else
using Tag = arbor::ad::Analytical;
constexpr const char* kName = "arm exact analytical (from 20 SCQP iterations)";
#endif

template <HessianKind H>
auto run(const VecX& w0, int max_iter) {
  const auto ws = std::make_unique<ArmWorkspace<Tag, true>>();
  const auto problem = arm_problem<N, M, Tag>(*ws, w_terminal);
  using Ctrl = arbor::nmpc::Nmpc<std::remove_cvref_t<decltype(problem)>, double, H>;
  const auto ctrl = std::make_unique<Ctrl>(problem);
  return solve_nmpc(*ctrl, plain(), w0, max_iter);
}

// As on the cart-pole, exact-Hessian SQP from the cold guess does not converge in 100
// iterations, so it starts from the plan of 20 SCQP iterations (multipliers reset).
TEST(IpoptArm, ExactHessianFromScqpPlan) {
  const PlainOcp o = plain();
  const auto warm = run<HessianKind::gauss_newton>(constant_guess(o), 20);
  EXPECT_EQ(warm.status, arbor::nmpc::NmpcStatus::iteration_limit);
  expect_matches_ipopt(kName, o, run<HessianKind::exact>(warm.point.w, 100), ipopt_solution(),
                       Tolerances{});
}

// Records (no assertion) where exact-Hessian SQP from the cold guess ends.
TEST(IpoptArm, ExactHessianColdStart) {
  const PlainOcp o = plain();
  const auto r = run<HessianKind::exact>(constant_guess(o), 100);
  const Kkt kkt = kkt_residuals(o, r.point);
  std::printf(
      "[nmpc-ipopt] arm exact from the cold guess: %s after %d iterations, objective "
      "%.10g (IPOPT %.10g), stationarity %.2e\n",
      to_string(r.status), r.info.iterations, o.objective(r.point.w), ipopt_solution().objective,
      kkt.stationarity);
}

}  // namespace
