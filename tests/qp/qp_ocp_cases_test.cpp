// OCP-structured solver on hand-made cases: a path parameter without cost (zero-Hessian state), an
// equality-constrained OCP, infeasible OCPs, non-finite and non-convex data, warm starts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "alloc_guard.hpp"
#include "arbor/qp/dense_qp_solver.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "qp_reference.hpp"
#include "status_names.hpp"

namespace arbor::qp {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace {
using arbor::qp::DenseQpProblem;
using arbor::qp::DenseQpSolver;
using arbor::qp::OcpQp;
using arbor::qp::OcpQpSolver;
using arbor::qp::QpStatus;
using arbor::qp::to_string;
namespace t = arbor::qp::test;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

/// Sets every field of every stage to neutral values: zero cost, identity dynamics, free bounds.
template <typename Qp>
void neutral(Qp& qp) {
  for (auto& s : qp.stage) {
    s.Q.setZero();
    s.S.setZero();
    s.R.setZero();
    s.q.setZero();
    s.r.setZero();
    s.A.setIdentity();
    s.B.setZero();
    s.b.setZero();
    s.C.setZero();
    s.D.setZero();
    s.lg.setConstant(-kInf);
    s.ug.setConstant(kInf);
    s.lbx.setConstant(-kInf);
    s.ubx.setConstant(kInf);
    s.lbu.setConstant(-kInf);
    s.ubu.setConstant(kInf);
  }
  qp.terminal.Q.setZero();
  qp.terminal.q.setZero();
  qp.terminal.C.setZero();
  qp.terminal.lg.setConstant(-kInf);
  qp.terminal.ug.setConstant(kInf);
  qp.terminal.lbx.setConstant(-kInf);
  qp.terminal.ubx.setConstant(kInf);
}

/// Solves qp with the OCP solver (in an allocation guard) and checks the KKT conditions and the
/// optimal value of the dense solver on the same data.
template <typename Qp>
void expect_optimal(const Qp& qp) {
  static OcpQpSolver<Qp> solver;
  static DenseQpProblem<double, Qp::nv, Qp::na> dp;
  static DenseQpSolver<double, Qp::nv, Qp::na> dense;
  const t::RefQp ref = t::to_ref(qp);
  t::to_dense(ref, dp);
  QpStatus st, sd;
  {
    arbor::test::NoAllocScope guard;
    ASSERT_EQ(solver.setup(qp), QpStatus::accepted);
    solver.cold_start();
    st = solver.solve();
    ASSERT_EQ(dense.setup(dp), QpStatus::accepted);
    dense.cold_start();
    sd = dense.solve();
  }
  ASSERT_EQ(st, QpStatus::solved) << to_string(st);
  ASSERT_EQ(sd, QpStatus::solved) << to_string(sd);
  const t::Kkt k = t::kkt_residuals(ref, solver.x(), solver.lam_x(), solver.lam_a());
  EXPECT_LE(k.primal, 1e-7 * k.pscale);
  EXPECT_LE(k.dual, 1e-7 * k.dscale);
  EXPECT_LE(k.complementarity, 1e-7 * k.pscale);
  const t::Kkt kd = t::kkt_residuals(ref, dense.x(), dense.lam_x(), dense.lam_a());
  EXPECT_NEAR(k.objective, kd.objective,
              t::objective_tolerance(k, solver.x(), solver.lam_x(), solver.lam_a(), 1e-9) +
                  t::objective_tolerance(kd, dense.x(), dense.lam_x(), dense.lam_a(), 1e-9));
}

/// Status of a cold solve (setup status when setup fails).
template <typename Qp>
QpStatus status_of(const Qp& qp) {
  static OcpQpSolver<Qp> solver;
  arbor::test::NoAllocScope guard;
  const QpStatus su = solver.setup(qp);
  if (su != QpStatus::accepted)
    return su;
  solver.cold_start();
  return solver.solve();
}

// x = (p, s): p tracks a reference with input u, s is a path parameter driven by the same input,
// without any quadratic cost; its progress is rewarded linearly and bounded.
using PathQp = OcpQp<double, 6, 2, 1, 1, 1>;

void make_path(PathQp& qp) {
  neutral(qp);
  for (int k = 0; k < 6; ++k) {
    auto& s = qp.stage[k];
    s.Q(0, 0) = 1;
    s.q(0) = -std::sin(0.5 * k);
    s.R(0, 0) = 0.01;
    s.B << 0.2, 0.1;
    s.lbu << -1;
    s.ubu << 1;
    s.lbx << -2, 0;
    s.ubx << 2, 0.25;
    s.C << 1, -1;  // p - s within a band
    s.lg << -0.5;
    s.ug << 0.5;
  }
  qp.stage[0].lbx << 0, 0;
  qp.stage[0].ubx << 0, 0;
  qp.terminal.q << 0, -1;  // reward progress of s (linear only)
  qp.terminal.lbx << -2, 0;
  qp.terminal.ubx << 2, 0.25;
  qp.terminal.C << 1, 0;
  qp.terminal.lg << -1;
  qp.terminal.ug << 1;
}

TEST(QpOcpCases, PathParameterWithoutCost) {
  static PathQp qp;
  make_path(qp);
  expect_optimal(qp);
}

TEST(QpOcpCases, AllZeroHessianIsAnLp) {
  static PathQp qp;
  make_path(qp);
  for (auto& s : qp.stage) {
    s.Q.setZero();
    s.R.setZero();
  }
  expect_optimal(qp);
}

TEST(QpOcpCases, EqualityConstrainedOcp) {
  using Qp = OcpQp<double, 5, 3, 2, 1, 2>;
  static Qp qp;
  std::mt19937 rng(7);
  t::RandomOcpOptions opt;
  opt.inf_fraction = 1.0;  // no inequality bounds at all
  t::random_ocp(qp, rng, opt);
  // stage constraints as equalities at values reachable from x_0: use a simulated trajectory
  Eigen::Vector3d x = qp.stage[0].lbx;
  for (auto& s : qp.stage) {
    const Eigen::Vector2d u(0.3, -0.2);
    s.lg = s.ug = s.C * x + s.D * u;
    x = s.A * x + s.B * u + s.b;
  }
  qp.terminal.lg = qp.terminal.ug = qp.terminal.C * x;
  expect_optimal(qp);
}

TEST(QpOcpCases, UnreachableTerminalStateIsInfeasible) {
  using Qp = OcpQp<double, 4, 1, 1, 0, 0>;
  static Qp qp;
  neutral(qp);
  for (auto& s : qp.stage) {
    s.Q << 1;
    s.R << 1;
    s.B << 1;
    s.lbu << -1;
    s.ubu << 1;
  }
  qp.stage[0].lbx << 0;
  qp.stage[0].ubx << 0;
  qp.terminal.lbx << 5;  // needs |u| = 1.25 on every stage
  EXPECT_EQ(status_of(qp), QpStatus::infeasible);
  qp.terminal.lbx << 3.5;  // reachable
  EXPECT_EQ(status_of(qp), QpStatus::solved);
}

TEST(QpOcpCases, ContradictoryStageConstraintIsInfeasible) {
  using Qp = OcpQp<double, 3, 2, 1, 2, 0>;
  static Qp qp;
  neutral(qp);
  for (auto& s : qp.stage) {
    s.Q.setIdentity();
    s.R << 1;
    s.A << 1, 0.1, 0, 1;
    s.B << 0, 0.1;
  }
  qp.stage[0].lbx << 1, 0;
  qp.stage[0].ubx << 1, 0;
  qp.stage[1].C << 1, 1, 1, 1;  // x1 + x2 >= 2 and x1 + x2 <= 1
  qp.stage[1].lg << 2, -kInf;
  qp.stage[1].ug << kInf, 1;
  EXPECT_EQ(status_of(qp), QpStatus::infeasible);
}

TEST(QpOcpCases, NonFiniteNonConvexAndBadBounds) {
  static PathQp qp;
  make_path(qp);
  EXPECT_EQ(status_of(qp), QpStatus::solved);
  qp.stage[2].A(1, 0) = kNan;
  EXPECT_EQ(status_of(qp), QpStatus::non_finite);
  make_path(qp);
  qp.stage[3].b(0) = kInf;
  EXPECT_EQ(status_of(qp), QpStatus::non_finite);
  make_path(qp);
  qp.terminal.q(1) = kNan;
  EXPECT_EQ(status_of(qp), QpStatus::non_finite);
  make_path(qp);
  qp.stage[4].lbu(0) = kNan;
  EXPECT_EQ(status_of(qp), QpStatus::non_finite);
  make_path(qp);
  qp.stage[1].ubx(0) = -3;
  EXPECT_EQ(status_of(qp), QpStatus::invalid_bounds);
  make_path(qp);
  qp.stage[5].R(0, 0) = -1;
  EXPECT_EQ(status_of(qp), QpStatus::non_convex);
  make_path(qp);
  qp.stage[5].S(0, 0) = 3;  // [Q S'; S R] = [1 3; 3 0.01] is indefinite
  EXPECT_EQ(status_of(qp), QpStatus::non_convex);
}

TEST(QpOcpCases, IterationCapReturnsBestIterate) {
  using Qp = OcpQp<double, 8, 4, 2, 1, 0>;
  static Qp qp;
  static OcpQpSolver<Qp> solver;
  std::mt19937 rng(11);
  t::RandomOcpOptions opt;
  opt.bound_width = 0.3;
  opt.cost_scale = 10;
  t::random_ocp(qp, rng, opt);
  QpStatus setup, full, capped;
  int full_iters = 0;
  {
    arbor::test::NoAllocScope guard;
    setup = solver.setup(qp);
    solver.cold_start();
    full = solver.solve();
    full_iters = solver.info().iterations;
    solver.settings().max_iter = 2;
    solver.cold_start();
    capped = solver.solve();
  }
  ASSERT_EQ(setup, QpStatus::accepted);
  ASSERT_EQ(full, QpStatus::solved);
  ASSERT_GT(full_iters, 2);
  EXPECT_EQ(capped, QpStatus::iteration_limit);
  EXPECT_LE(solver.info().iterations, 2);
  // the reported residuals are those of the returned iterate
  const t::Kkt k = t::kkt_residuals(t::to_ref(qp), solver.x(), solver.lam_x(), solver.lam_a());
  EXPECT_NEAR(k.primal, std::max(0.0, solver.info().primal_residual), 1e-9);
  EXPECT_NEAR(k.dual, solver.info().dual_residual, 1e-9);
}

TEST(QpOcpCases, ResidualsOfLongSolvesBelongToTheReturnedPoint) {
  // Cold solves of many iterations: the active-set loop updates A x, H x and A' lam after
  // blocked steps instead of recomputing them (active_set.hpp); the status and the residuals it
  // reports must still be those of the returned point, computed from the data.
  using Qp = OcpQp<double, 12, 4, 2, 2, 1>;
  static Qp qp;
  static OcpQpSolver<Qp> solver;
  t::RandomOcpOptions opt;
  opt.bound_width = 0.2;
  opt.cost_scale = 30;
  int longest = 0;
  for (unsigned seed = 0; seed < 8; ++seed) {
    std::mt19937 rng(300 + seed);
    t::random_ocp(qp, rng, opt);
    const t::RefQp ref = t::to_ref(qp);
    const auto check = [&](const auto& s, QpStatus su, QpStatus st) {
      SCOPED_TRACE(seed);
      ASSERT_EQ(su, QpStatus::accepted);
      ASSERT_EQ(st, QpStatus::solved);
      const t::Kkt k = t::kkt_residuals(ref, s.x(), s.lam_x(), s.lam_a());
      EXPECT_LE(k.primal, 1e-7 * k.pscale);
      EXPECT_LE(k.dual, 1e-7 * k.dscale);
      EXPECT_NEAR(k.primal, std::max(0.0, s.info().primal_residual), 1e-12 * k.pscale);
      EXPECT_NEAR(k.dual, s.info().dual_residual, 1e-12 * k.dscale);
      EXPECT_NEAR(k.complementarity, s.info().complementarity, 1e-12 * k.pscale);
      EXPECT_NEAR(k.objective, s.info().objective, 1e-12 * (1 + std::abs(k.objective)));
      longest = std::max(longest, s.info().iterations);
    };
    QpStatus su, st;
    {
      arbor::test::NoAllocScope guard;
      su = solver.setup(qp);
      solver.cold_start();
      st = solver.solve();
    }
    check(solver, su, st);
  }
  EXPECT_GT(longest, 20);  // long enough for updated products and their periodic refresh
}

TEST(QpOcpCases, WarmStartFromPerturbedProblemNeedsFarFewerIterations) {
  using Qp = OcpQp<double, 16, 4, 2, 1, 0>;
  static Qp qp;
  static OcpQpSolver<Qp> solver;
  int cold = 0, warm = 0, changes_cold = 0, changes_warm = 0;
  std::mt19937 rng(21);
  t::RandomOcpOptions opt;
  opt.bound_width = 0.3;
  opt.cost_scale = 10;
  t::random_ocp(qp, rng, opt);
  std::normal_distribution<double> nd(0.0, 1.0);
  QpStatus u1, u2, s1, s2, s3;
  {
    arbor::test::NoAllocScope guard;
    u1 = solver.setup(qp);
    solver.cold_start();
    s1 = solver.solve();  // the solution of the nominal problem is the warm start
  }
  for (auto& s : qp.stage) {  // perturb the costs by about 1 %
    for (int i = 0; i < 4; ++i)
      s.q(i) *= 1 + 0.01 * nd(rng);
    for (int i = 0; i < 2; ++i)
      s.r(i) *= 1 + 0.01 * nd(rng);
  }
  {
    arbor::test::NoAllocScope guard;
    u2 = solver.setup(qp);  // keeps the iterate
    s2 = solver.solve();
    warm = solver.info().iterations;
    changes_warm = solver.info().active_set_changes;
    solver.cold_start();
    s3 = solver.solve();
    cold = solver.info().iterations;
    changes_cold = solver.info().active_set_changes;
  }
  ASSERT_EQ(u1, QpStatus::accepted);
  ASSERT_EQ(u2, QpStatus::accepted);
  ASSERT_EQ(s1, QpStatus::solved);
  ASSERT_EQ(s2, QpStatus::solved);
  ASSERT_EQ(s3, QpStatus::solved);
  RecordProperty("cold_iterations", cold);
  RecordProperty("warm_iterations", warm);
  EXPECT_GE(changes_cold, 10);
  EXPECT_LE(4 * warm, cold) << "warm " << warm << " cold " << cold;
  EXPECT_LE(4 * changes_warm, changes_cold);
}

}  // namespace
