// Warm starts on an unchanged working set end after one step (issue 15): the Riccati backend
// holds the working bounds of the inputs and of x_0 exactly (the variable is fixed and removed
// from the recursion, ocp_riccati_backend.hpp), and a full step that the proximal weights of the
// remaining bounds and path rows would leave outside the tolerance is refined once on the same
// factorization (active_set.hpp, refine_step). Before, every active constraint was held by the
// weight 1/eps, the first step missed it by ~eps |lam| and a second iteration was needed.
// References: a closed form (a linear cost pushed into the active bounds leaves the primal
// solution where it is and moves only those bounds' multipliers by exactly the push) and the KKT
// residuals of qp_reference.hpp (dynamic Eigen, from the problem's definition).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "alloc_guard.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "kinova_qp.hpp"
#include "qp_reference.hpp"
#include "status_names.hpp"

namespace arbor::qp {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace {
using arbor::qp::Convexity;
using arbor::qp::OcpQp;
using arbor::qp::OcpQpSolver;
using arbor::qp::QpSettings;
using arbor::qp::QpStatus;
namespace t = arbor::qp::test;

constexpr int N = 8, NX = 4, NU = 2, NG = 1, NGN = 1;
using Qp = OcpQp<double, N, NX, NU, NG, NGN>;
constexpr int NW = NX + NU;  // variables per path stage, written out here (flat layout)

/// Which kind of variable the flat index i is (problem.hpp's layout: stage k holds x_k then u_k).
enum class Kind { x0, state, input };
Kind kind_of(int i) {
  if (i < NX)
    return Kind::x0;
  return i < N * NW && i % NW >= NX ? Kind::input : Kind::state;
}

/// Pushes the linear cost of every variable with an active bound by `push` into its bound:
/// the same x stays optimal and those bounds' multipliers grow by exactly `push` (stationarity
/// H x + g + lam_x + A' lam_a = 0 holds with g_i - push sign(lam_i) and lam_i + push sign(lam_i)).
/// Returns the expected bound multipliers.
Eigen::VectorXd push_into_bounds(Qp& qp, const Eigen::VectorXd& lam_x, double push) {
  Eigen::VectorXd expect = lam_x;
  for (int i = 0; i < Qp::nv; ++i) {
    if (lam_x(i) == 0)
      continue;
    const double sg = lam_x(i) > 0 ? 1.0 : -1.0;
    expect(i) += push * sg;
    const int k = i / NW, loc = i % NW;
    if (k == N)
      qp.terminal.q(loc) -= push * sg;
    else if (loc < NX)
      qp.stage[k].q(loc) -= push * sg;
    else
      qp.stage[k].r(loc - NX) -= push * sg;
  }
  return expect;
}

TEST(QpExactBounds, WarmSolveOnUnchangedActiveBoundsTakesOneStep) {
  static Qp qp;
  static OcpQpSolver<Qp> s;
  t::RandomOcpOptions opt;
  opt.bound_width = 0.3;  // bounds close to the trajectory: many active
  opt.cost_scale = 5.0;
  std::mt19937 rng(1515);
  t::random_ocp(qp, rng, opt);
  ASSERT_EQ(s.setup(qp), QpStatus::accepted);
  s.cold_start();
  ASSERT_EQ(s.solve(), QpStatus::solved);
  const Eigen::VectorXd x_cold = s.x();
  const Eigen::VectorXd lam_cold = s.lam_x();
  const Eigen::VectorXd lam_a_cold = s.lam_a();
  // the working set must hold every kind of bound: exact (x_0, inputs) and weighted (states)
  int active[3] = {0, 0, 0};
  for (int i = 0; i < Qp::nv; ++i)
    active[static_cast<int>(kind_of(i))] += lam_cold(i) != 0 ? 1 : 0;
  ASSERT_EQ(active[0], NX);  // x_0 is fixed (equal bounds)
  ASSERT_GE(active[1], 1);
  ASSERT_GE(active[2], 1);

  // a push of 0.5: with the weight 1/eps = 1e6 the first step used to miss each bound by
  // ~5e-7, fifty times tol_primal
  const Eigen::VectorXd lam_expect = push_into_bounds(qp, lam_cold, 0.5);
  QpStatus st;
  {
    arbor::test::NoAllocScope guard;
    ASSERT_EQ(s.update(Convexity::assumed), QpStatus::accepted);
    st = s.solve();
  }
  ASSERT_EQ(st, QpStatus::solved);
  EXPECT_EQ(s.info().iterations, 1);
  EXPECT_EQ(s.info().active_set_changes, 0);
  const double scale = 1 + x_cold.cwiseAbs().maxCoeff();
  EXPECT_LE((s.x() - x_cold).cwiseAbs().maxCoeff(), 1e-9 * scale);
  EXPECT_LE((s.lam_x() - lam_expect).cwiseAbs().maxCoeff(), 1e-7 * (1 + lam_expect.norm()));
  EXPECT_LE((s.lam_a() - lam_a_cold).cwiseAbs().maxCoeff(), 1e-7 * (1 + lam_expect.norm()));
  const t::Kkt k = t::kkt_residuals(t::to_ref(qp), s.x(), s.lam_x(), s.lam_a());
  EXPECT_LE(k.primal, 1e-9 * k.pscale);
  EXPECT_LE(k.dual, 1e-8 * k.dscale);
  EXPECT_LE(k.complementarity, 1e-9 * k.pscale);
}

TEST(QpExactBounds, KinovaWarmUpdateTakesOneStep) {
  // The benchmark's real-time path (bench/qp: nominal solve, then the perturbed data through
  // update(Convexity::assumed)): 2 iterations before, the second only to pull the 16 bounds of
  // x_0 and 26 state bounds the first step missed by up to 2.2e-7 within tolerance.
  using Kinova = arbor::bench::KinovaQp<double, 1>;
  static Kinova nominal, perturbed, live;
  static OcpQpSolver<Kinova> s;
  arbor::bench::make_kinova_qp(nominal, 1);
  arbor::bench::make_kinova_qp(perturbed, 1, 1e-3, 0.01);
  QpSettings<double> set;
  set.max_iter = 1000;
  live = nominal;
  ASSERT_EQ(s.setup(live, set), QpStatus::accepted);
  s.cold_start();
  ASSERT_EQ(s.solve(), QpStatus::solved);
  live = perturbed;
  ASSERT_EQ(s.update(Convexity::assumed), QpStatus::accepted);
  ASSERT_EQ(s.solve(), QpStatus::solved);
  EXPECT_EQ(s.info().iterations, 1);
  const t::Kkt k = t::kkt_residuals(t::to_ref(live), s.x(), s.lam_x(), s.lam_a());
  EXPECT_LE(k.primal, 1e-8 * k.pscale);
  EXPECT_LE(k.dual, 1e-8 * k.dscale);
  EXPECT_LE(k.complementarity, 1e-8 * k.pscale);
}

}  // namespace
