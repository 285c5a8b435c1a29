// Robustness of the active-set core (issue 15): termination judged per constraint (invariant to
// scaling a row), fast scale-invariant infeasibility detection and a clear status when the
// working-set rule has nothing left to change. The anti-cycling rule on the float solve of the
// Kinova-sized benchmark problem, which used to stall at the iteration cap, is in
// qp_robustness_kinova.cpp (linked into the same test; a separate unit keeps each compile
// short). Every expected value is derived by hand in the comments or recomputed from the data
// (qp_reference.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "alloc_guard.hpp"
#include "arbor/qp/dense_qp_solver.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "qp_reference.hpp"
#include "qp_robustness.hpp"
#include "status_names.hpp"

namespace arbor::qp {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace {
using arbor::qp::DenseQpProblem;
using arbor::qp::DenseQpSolver;
using arbor::qp::OcpQp;
using arbor::qp::OcpQpSolver;
using arbor::qp::QpSettings;
using arbor::qp::QpStatus;
namespace t = arbor::qp::test;
constexpr double kInf = std::numeric_limits<double>::infinity();

using t::cold_solve;

template <int NV, int NA>
t::RefQp ref_of(const DenseQpProblem<double, NV, NA>& p) {
  t::RefQp r;
  r.H = p.H;
  r.g = p.g;
  r.A = p.A;
  r.lbx = p.lbx;
  r.ubx = p.ubx;
  r.lba = p.lba;
  r.uba = p.uba;
  return r;
}

// ---- feasibility judged per constraint ----------------------------------------------------------

TEST(QpRobustness, RowsScaledVeryDifferentlyAreEachSatisfied) {
  // min 1/2 |x - (2.75, 0)|^2  s.t.  x1 >= 2.75,  s (x1 + x2) <= s,  b (x1 - x2) <= 10 b.
  // The cold start (2.75, 0) violates the second row by 1.75 s, 175 % of its own size; with
  // b = 1e6 that is far below a tolerance scaled by |A x| ~ 2.75e6. By hand: both the bound and
  // the small row are active, x = (2.75, -1.75); stationarity (0, -1.75) + lam_x1 e1 +
  // s lam_a0 (1, 1) = 0 gives s lam_a0 = 1.75, lam_x1 = -1.75; the third row is inactive (4.5).
  static DenseQpProblem<double, 2, 2> p;
  static DenseQpSolver<double, 2, 2> s;
  for (const double small : {1.0, 1e-6}) {
    for (const double big : {1.0, 1e6}) {
      SCOPED_TRACE(::testing::Message() << "row scales " << small << ", " << big);
      p.H.setIdentity();
      p.g << -2.75, 0;
      p.A << small, small, big, -big;
      p.lbx << 2.75, -kInf;
      p.ubx << kInf, kInf;
      p.lba << -kInf, -kInf;
      p.uba << small, 10 * big;
      const QpStatus st = cold_solve(s, p, QpSettings<double>{});
      ASSERT_EQ(st, QpStatus::solved);
      EXPECT_NEAR(s.x()(0), 2.75, 1e-8);
      EXPECT_NEAR(s.x()(1), -1.75, 1e-8);
      EXPECT_NEAR(s.lam_x()(0), -1.75, 1e-7);
      EXPECT_NEAR(s.lam_a()(0) * small, 1.75, 1e-7);
      EXPECT_NEAR(s.lam_a()(1), 0, 1e-12);
      // every row within its own scale: violation / |a_i| against the x scale
      const Eigen::Vector2d z = p.A * s.x();
      for (int i = 0; i < 2; ++i) {
        const double v = std::max(p.lba(i) - z(i), z(i) - p.uba(i)) / p.A.row(i).norm();
        EXPECT_LE(v, 1e-8 * (1 + s.x().cwiseAbs().maxCoeff())) << "row " << i;
      }
    }
  }
}

// ---- infeasibility: scale-invariant certificate, a handful of iterations ------------------------

TEST(QpRobustness, UnreachableRowOnABoxIsInfeasibleWhateverTheCostScale) {
  // 0 <= x <= 1 and c x >= 2 c: infeasible for every c > 0 and every Hessian h. The multipliers
  // of the bound and of the row grow in opposite directions; a large h slowed the former
  // absolute test (153 iterations for h = 100, the cap for h = 1e4).
  static DenseQpProblem<double, 1, 1> p;
  static DenseQpSolver<double, 1, 1> s;
  for (const double h : {1.0, 1e2, 1e4, 1e6}) {
    for (const double c : {1.0, 1e-6, 1e6}) {
      SCOPED_TRACE(::testing::Message() << "h " << h << " row scale " << c);
      p.H << h;
      p.g << 0;
      p.A << c;
      p.lbx << 0;
      p.ubx << 1;
      p.lba << 2 * c;
      p.uba << kInf;
      EXPECT_EQ(cold_solve(s, p, QpSettings<double>{}), QpStatus::infeasible);
      EXPECT_LE(s.info().iterations, 8);
    }
  }
}

TEST(QpRobustness, NearlyInfeasibleButFeasibleBoxIsSolved) {
  // 0 <= x <= 1, x >= 1 - d: feasible (x = 1 when the cost pushes down), also at d = 0
  // (a degenerate vertex); no certificate may fire.
  static DenseQpProblem<double, 1, 1> p;
  static DenseQpSolver<double, 1, 1> s;
  for (const double d : {1e-3, 1e-7, 0.0}) {
    SCOPED_TRACE(::testing::Message() << "d " << d);
    p.H << 100;
    p.g << 0;
    p.A << 1;
    p.lbx << 0;
    p.ubx << 1;
    p.lba << 1 - d;
    p.uba << kInf;
    ASSERT_EQ(cold_solve(s, p, QpSettings<double>{}), QpStatus::solved);
    EXPECT_NEAR(s.x()(0), 1 - d, 1e-8);
  }
}

// Double integrator, N = 3, dt = 0.5, x_0 = 0, |u| <= 1: v_N = dt (u_0 + u_1 + u_2) <= 1.5.
using Di = OcpQp<double, 3, 2, 1, 0, 0>;
void double_integrator(Di& qp, double v_target, double r) {
  constexpr double dt = 0.5;
  for (auto& st : qp.stage) {
    st.Q.setIdentity();
    st.S.setZero();
    st.R.setConstant(r);
    st.q.setZero();
    st.r.setZero();
    st.A << 1, dt, 0, 1;
    st.B << 0.5 * dt * dt, dt;
    st.b.setZero();
    st.lbx.setConstant(-kInf);
    st.ubx.setConstant(kInf);
    st.lbu << -1;
    st.ubu << 1;
  }
  qp.stage[0].lbx.setZero();
  qp.stage[0].ubx.setZero();
  qp.terminal.Q.setIdentity();
  qp.terminal.q.setZero();
  qp.terminal.lbx << -kInf, v_target;
  qp.terminal.ubx << kInf, v_target;
}

TEST(QpRobustness, DoubleIntegratorUnreachableVelocityIsInfeasibleQuickly) {
  static Di qp;
  static OcpQpSolver<Di> s;
  for (const double r : {1.0, 100.0}) {
    for (const double v : {5.0, 1.6}) {
      SCOPED_TRACE(::testing::Message() << "r " << r << " v_N " << v);
      double_integrator(qp, v, r);
      EXPECT_EQ(cold_solve(s, qp, QpSettings<double>{}), QpStatus::infeasible);
      EXPECT_LE(s.info().iterations, 10);  // was the cap (200) for v = 5, r = 100
    }
  }
}

TEST(QpRobustness, DoubleIntegratorReachableVelocityKeepsTheInputBounds) {
  static Di qp;
  static OcpQpSolver<Di> s;
  for (const double v : {1.4, 1.5}) {  // 1.5: every input at its bound (degenerate)
    SCOPED_TRACE(::testing::Message() << "v_N " << v);
    double_integrator(qp, v, 100.0);
    ASSERT_EQ(cold_solve(s, qp, QpSettings<double>{}), QpStatus::solved);
    double sum = 0;
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(std::abs(s.input(k)(0)), 1 + 1e-8);
      sum += s.input(k)(0);
    }
    EXPECT_NEAR(0.5 * sum, v, 1e-7);  // tol_primal 1e-8 relative to the iterate's scale
    EXPECT_NEAR(s.state(3)(1), v, 1e-7);
  }
}

// ---- nothing left to change: a clear status, not the iteration cap -----------------------------

void dense_test_problem(DenseQpProblem<double, 4, 3>& p) {
  // a strictly convex QP with entries of magnitude ~1e3 (round-off ~1e-13 relative)
  p.H << 4, 1, 0, 0.5, 1, 3, 0.2, 0, 0, 0.2, 2, 0.1, 0.5, 0, 0.1, 1;
  p.H *= 1e3;
  p.g << -3e3, 1e3, -2e3, 5e2;
  p.A << 1, 1, 1, 1, 1, -1, 0, 0, 0, 0, 1, -1;
  p.lbx.setConstant(-2);
  p.ubx.setConstant(2);
  p.lba << -kInf, -0.5, -0.3;
  p.uba << 1, 0.5, 0.3;
}

TEST(QpRobustness, TolerancesBelowRoundOffEndWithAStatusAndTheReturnedResiduals) {
  static DenseQpProblem<double, 4, 3> p;
  static DenseQpSolver<double, 4, 3> s;
  dense_test_problem(p);
  ASSERT_EQ(cold_solve(s, p, QpSettings<double>{}), QpStatus::solved);
  const Eigen::Vector4d x_ref = s.x();
  QpSettings<double> tight;
  tight.tol_primal = tight.tol_dual = tight.tol_comp = 1e-30;
  tight.max_iter = 500;
  const QpStatus st = cold_solve(s, p, tight);
  EXPECT_TRUE(st == QpStatus::stalled || st == QpStatus::solved) << st;
  EXPECT_LE(s.info().iterations, 40);  // not the cap
  const t::Kkt k = t::kkt_residuals(ref_of(p), s.x(), s.lam_x(), s.lam_a());
  EXPECT_NEAR(k.primal, std::max(0.0, s.info().primal_residual), 1e-15 * k.pscale);
  EXPECT_NEAR(k.dual, s.info().dual_residual, 1e-15 * k.dscale);
  EXPECT_LE(k.primal, 1e-12 * k.pscale);
  EXPECT_LE(k.dual, 1e-12 * k.dscale);
  EXPECT_LE((s.x() - x_ref).cwiseAbs().maxCoeff(), 1e-7);
}

TEST(QpRobustness, ComplementarityTighterThanTheDualToleranceStillTerminates) {
  // the contour example's SQP mode: loose primal and dual tolerances, strict complementarity
  static DenseQpProblem<double, 4, 3> p;
  static DenseQpSolver<double, 4, 3> s;
  dense_test_problem(p);
  QpSettings<double> mixed;
  mixed.tol_primal = 1e-3;
  mixed.tol_dual = 1e-1;
  mixed.tol_comp = 1e-8;
  const QpStatus st = cold_solve(s, p, mixed);
  ASSERT_EQ(st, QpStatus::solved);
  const t::Kkt k = t::kkt_residuals(ref_of(p), s.x(), s.lam_x(), s.lam_a());
  EXPECT_LE(k.complementarity, 1e-8 * k.pscale);
  const t::EnumResult e = t::enumerate_active_sets(ref_of(p));
  ASSERT_TRUE(e.found);
  EXPECT_NEAR(k.objective, e.objective,
              t::objective_tolerance(k, s.x(), s.lam_x(), s.lam_a(), 1e-6));
}

}  // namespace
