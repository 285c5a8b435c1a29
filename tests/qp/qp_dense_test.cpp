// Dense solver on the known failure cases of CasADi's QRQP and on bad input: every solution is
// checked against the KKT conditions (recomputed with dynamic Eigen) and the optimal value of an
// exhaustive active-set enumeration; infeasible problems must never be reported as solved.
#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <random>

#include "alloc_guard.hpp"
#include "arbor/qp/dense_qp_solver.hpp"
#include "qp_reference.hpp"
#include "status_names.hpp"

namespace arbor::qp {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace {
using arbor::qp::DenseQpProblem;
using arbor::qp::DenseQpSolver;
using arbor::qp::QpStatus;
using arbor::qp::to_string;
namespace t = arbor::qp::test;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

template <int NV, int NA>
struct Case {
  DenseQpProblem<double, NV, NA> p;
  DenseQpSolver<double, NV, NA> s;
  QpStatus setup_status = QpStatus::not_setup;

  QpStatus run() {
    arbor::test::NoAllocScope guard;
    setup_status = s.setup(p);
    if (setup_status != QpStatus::accepted)
      return setup_status;
    s.cold_start();
    return s.solve();
  }
  t::RefQp ref() const {
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
  /// Solves and checks: status solved, KKT residuals, optimal value of the enumeration.
  void expect_optimal() {
    const QpStatus st = run();
    ASSERT_EQ(st, QpStatus::solved) << to_string(st) << " after " << s.info().iterations;
    const t::RefQp r = ref();
    const t::Kkt k = t::kkt_residuals(r, s.x(), s.lam_x(), s.lam_a());
    EXPECT_LE(k.primal, 1e-7 * k.pscale);
    EXPECT_LE(k.dual, 1e-7 * k.dscale);
    EXPECT_LE(k.complementarity, 1e-7 * k.pscale);
    const t::EnumResult e = t::enumerate_active_sets(r);
    ASSERT_TRUE(e.found);
    EXPECT_NEAR(k.objective, e.objective,
                t::objective_tolerance(k, s.x(), s.lam_x(), s.lam_a(), 1e-8));
  }
};

template <int NV, int NA>
void free_bounds(DenseQpProblem<double, NV, NA>& p) {
  p.lbx.setConstant(-kInf);
  p.ubx.setConstant(kInf);
}

TEST(QpDense, CasadiIssue3141ZeroHessian) {
  // min x  s.t.  0 <= 2x + 1 <= 2, H = 0 (QRQP failed on it)
  static Case<1, 1> c;
  c.p.H.setZero();
  c.p.g << 1;
  c.p.A << 2;
  free_bounds(c.p);
  c.p.lba << -1;
  c.p.uba << 1;
  c.expect_optimal();
  EXPECT_NEAR(c.s.x()(0), -0.5, 1e-8);
  EXPECT_NEAR(c.s.lam_a()(0), -0.5, 1e-7);
}

TEST(QpDense, RedundantAndLinearlyDependentConstraints) {
  // min 1/2|x - (1, 2)|^2 s.t. x1 + x2 <= 1 (three times, once scaled), x1 - x2 = -0.5 (twice)
  static Case<2, 5> c;
  c.p.H.setIdentity();
  c.p.g << -1, -2;
  c.p.A << 1, 1, 2, 2, 1, 1, 1, -1, 1, -1;
  free_bounds(c.p);
  c.p.lba << -kInf, -kInf, -kInf, -0.5, -0.5;
  c.p.uba << 1, 2, 1, -0.5, -0.5;
  c.expect_optimal();
  EXPECT_NEAR(c.s.x()(0), 0.25, 1e-7);
  EXPECT_NEAR(c.s.x()(1), 0.75, 1e-7);
}

TEST(QpDense, ZeroHessianDirection) {
  // x2 has no cost curvature (like a path parameter) and a linear cost: it goes to its bound
  static Case<2, 1> c;
  c.p.H << 1, 0, 0, 0;
  c.p.g << -1, 1;
  c.p.A << 1, 1;
  c.p.lbx << -kInf, -2;
  c.p.ubx << kInf, 3;
  c.p.lba << -kInf;
  c.p.uba << 10;
  c.expect_optimal();
  EXPECT_NEAR(c.s.x()(0), 1, 1e-7);
  EXPECT_NEAR(c.s.x()(1), -2, 1e-7);
}

TEST(QpDense, DegenerateVertexLinearProgram) {
  // four constraints active at (1, 1) in 2-D: degenerate active set; an LP
  static Case<2, 2> c;
  c.p.H.setZero();
  c.p.g << -1, -1;
  c.p.A << 1, 1, 1, -1;
  c.p.lbx << -5, -5;
  c.p.ubx << 1, 1;
  c.p.lba << -kInf, -kInf;
  c.p.uba << 2, 0;
  c.expect_optimal();
  EXPECT_NEAR(c.s.x()(0), 1, 1e-7);
  EXPECT_NEAR(c.s.x()(1), 1, 1e-7);
}

TEST(QpDense, BealeCyclingLinearProgram) {
  // Beale's example (as in Chvatal, Linear Programming, ch. 3), on which the simplex method with
  // the largest-coefficient rule cycles at the degenerate start vertex x = 0 (both rows active
  // at zero): min -3/4 x1 + 150 x2 - 1/50 x3 + 6 x4, 1/4 x1 - 60 x2 - 1/25 x3 + 9 x4 <= 0,
  // 1/2 x1 - 90 x2 - 1/50 x3 + 3 x4 <= 0, x >= 0, x3 <= 1. Optimum x = (1/25, 0, 1, 0), value
  // -1/20 (by hand: multipliers 3/2 on row 2, 1/20 on x3 <= 1, reduced costs 15 and 21/2 on
  // x2, x4); the cold start is that degenerate vertex
  static Case<4, 2> c;
  c.p.H.setZero();
  c.p.g << -0.75, 150, -0.02, 6;
  c.p.A << 0.25, -60, -0.04, 9, 0.5, -90, -0.02, 3;
  c.p.lbx << 0, 0, 0, 0;
  c.p.ubx << kInf, kInf, 1, kInf;
  c.p.lba << -kInf, -kInf;
  c.p.uba << 0, 0;
  c.expect_optimal();
  EXPECT_NEAR(c.s.x()(0), 0.04, 1e-9);
  EXPECT_NEAR(c.s.x()(1), 0, 1e-9);
  EXPECT_NEAR(c.s.x()(2), 1, 1e-9);
  EXPECT_NEAR(c.s.x()(3), 0, 1e-9);
  EXPECT_NEAR(c.s.info().objective, -0.05, 1e-9);
  EXPECT_LE(c.s.info().iterations, 20);
}

TEST(QpDense, EqualityConstrained) {
  static Case<3, 2> c;
  c.p.H << 4, 1, 0, 1, 3, 1, 0, 1, 2;
  c.p.g << 1, -2, 0.5;
  c.p.A << 1, 1, 1, 1, -1, 2;
  free_bounds(c.p);
  c.p.lba << 1, -0.5;
  c.p.uba << 1, -0.5;
  c.expect_optimal();
}

TEST(QpDense, LinearProgram) {
  static Case<3, 3> c;
  c.p.H.setZero();
  c.p.g << -1, -2, 0.5;
  c.p.A << 1, 1, 1, 1, -1, 0, 0, 1, -1;
  c.p.lbx << 0, 0, 0;
  c.p.ubx << 4, 3, 5;
  c.p.lba << -kInf, -1, -2;
  c.p.uba << 5, 1, 2;
  c.expect_optimal();
}

TEST(QpDense, MerelyConvexWithFreeDirection) {
  // H singular and g orthogonal to its null space: the solution set is a segment
  static Case<2, 1> c;
  c.p.H << 1, 1, 1, 1;
  c.p.g << -1, -1;
  c.p.A << 1, -1;
  c.p.lbx << -3, -3;
  c.p.ubx << 3, 3;
  c.p.lba << -1;
  c.p.uba << 1;
  c.expect_optimal();
}

TEST(QpDense, InfeasibleBoundAndRow) {
  static Case<1, 1> c;
  c.p.H << 1;
  c.p.g << 0;
  c.p.A << 1;
  c.p.lbx << 0;
  c.p.ubx << 1;
  c.p.lba << 2;
  c.p.uba << kInf;
  EXPECT_EQ(c.run(), QpStatus::infeasible);
}

TEST(QpDense, InfeasibleRows) {
  static Case<2, 2> c;
  c.p.H.setIdentity();
  c.p.g << 0, 0;
  c.p.A << 1, 1, 1, 1;
  c.p.lbx << -10, -10;
  c.p.ubx << 10, 10;
  c.p.lba << 3, -kInf;
  c.p.uba << kInf, 1;
  EXPECT_EQ(c.run(), QpStatus::infeasible);
}

TEST(QpDense, InfeasibleEqualities) {
  static Case<2, 2> c;
  c.p.H.setZero();
  c.p.g << 1, 0;
  c.p.A << 1, 1, 2, 2;
  free_bounds(c.p);
  c.p.lba << 1, 3;
  c.p.uba << 1, 3;
  EXPECT_EQ(c.run(), QpStatus::infeasible);
}

TEST(QpDense, Unbounded) {
  static Case<2, 1> c;
  c.p.H << 1, 0, 0, 0;
  c.p.g << 0, -1;
  c.p.A << 1, 0;
  c.p.lbx << -kInf, 0;
  c.p.ubx << kInf, kInf;
  c.p.lba << -1;
  c.p.uba << 1;
  EXPECT_EQ(c.run(), QpStatus::unbounded);
}

/// A warm start whose multipliers name the solution's working set, from a point that violates a
/// constraint inactive at the solution: the first step on the named working set satisfies it, so
/// the solve makes no working-set change (the rule used to add the violated bound first and drop
/// it at the next iteration: 2 iterations, 2 changes (checked against the former code); the contour
/// closed loop's terminal velocity bound did this every sample, bench/nmpc/RESULTS.md). Closed
/// form: min 1/2 |x - (2, 0)|^2, x <= (1, 1): x = (1, 0), lam_x = (1, 0).
TEST(QpDense, WarmStartStepsOnItsWorkingSetBeforeAdding) {
  static Case<2, 1> c;
  c.p.H.setIdentity();
  c.p.g << -2, 0;
  c.p.A << 1, 1;
  c.p.lbx.setConstant(-kInf);
  c.p.ubx << 1, 1;
  c.p.lba << -kInf;
  c.p.uba << kInf;
  QpStatus st;
  {
    arbor::test::NoAllocScope guard;
    ASSERT_EQ(c.s.setup(c.p), QpStatus::accepted);
    c.s.edit_warm_start([](auto& x, auto& lam_x, auto& lam_a) {
      x << 1, 1.5;  // x_2 = 1.5 violates x_2 <= 1
      lam_x << 1, 0;
      lam_a << 0;
    });
    st = c.s.solve();
  }
  ASSERT_EQ(st, QpStatus::solved);
  EXPECT_EQ(c.s.info().active_set_changes, 0);
  EXPECT_LE(c.s.info().iterations, 2);
  EXPECT_NEAR(c.s.x()[0], 1, 1e-7);  // (the QP's tolerances: 1e-8 relative)
  EXPECT_NEAR(c.s.x()[1], 0, 1e-7);
  EXPECT_NEAR(c.s.lam_x()[0], 1, 1e-7);
  EXPECT_EQ(c.s.lam_x()[1], 0);
  // from zero multipliers (no working set named: the rule adds constraints from the first
  // iteration) the same solution, with x_1 <= 1 added on the way
  {
    arbor::test::NoAllocScope guard;
    c.s.edit_warm_start([](auto& x, auto& lam_x, auto&) {
      x << 1, 1.5;
      lam_x.setZero();
    });
    st = c.s.solve();
  }
  ASSERT_EQ(st, QpStatus::solved);
  EXPECT_GE(c.s.info().active_set_changes, 1);
  EXPECT_NEAR(c.s.x()[0], 1, 1e-7);  // (the QP's tolerances: 1e-8 relative)
  EXPECT_NEAR(c.s.x()[1], 0, 1e-7);
}

TEST(QpDense, NonFiniteDataAndBadBounds) {
  static Case<2, 1> c;
  auto reset = [] {
    c.p.H.setIdentity();
    c.p.g << 1, 1;
    c.p.A << 1, 1;
    c.p.lbx << -1, -1;
    c.p.ubx << 1, 1;
    c.p.lba << -1;
    c.p.uba << 1;
  };
  reset();
  EXPECT_EQ(c.run(), QpStatus::solved);
  c.p.H(0, 1) = kNan;
  EXPECT_EQ(c.run(), QpStatus::non_finite);
  reset();
  c.p.g(1) = kInf;
  EXPECT_EQ(c.run(), QpStatus::non_finite);
  reset();
  c.p.A(0, 0) = kNan;
  EXPECT_EQ(c.run(), QpStatus::non_finite);
  reset();
  c.p.lba(0) = kNan;
  EXPECT_EQ(c.run(), QpStatus::non_finite);
  reset();
  c.p.lbx(1) = 2;
  EXPECT_EQ(c.run(), QpStatus::invalid_bounds);
  reset();
  c.p.H(1, 1) = -1;
  EXPECT_EQ(c.run(), QpStatus::non_convex);
  EXPECT_EQ(c.s.solve(), QpStatus::not_setup);
}

// The convexity check of setup() and update() (qp/data_checks.hpp, is_psd: a Cholesky of the
// block plus a relative slack by the register-blocked kernel) on sizes that are no multiple of a
// block edge or a vector width, against the closed form H = V diag(d) V' (V orthogonal, from
// Eigen's QR of a random matrix): a semidefinite H (some d = 0) and a definite one are accepted,
// one eigenvalue of -1e-3 |d|_max is refused, and only the upper triangle is read (NaN below).
template <int n>
void check_convexity_check(std::mt19937& rng) {
  std::normal_distribution<double> nd(0.0, 1.0);
  const Eigen::MatrixXd g = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return nd(rng); });
  const Eigen::MatrixXd v = Eigen::HouseholderQR<Eigen::MatrixXd>(g).householderQ();
  auto build = [&](const Eigen::VectorXd& d) {
    Eigen::Matrix<double, n, n> h = v * d.asDiagonal() * v.transpose();
    for (int j = 0; j < n; ++j)
      for (int i = j + 1; i < n; ++i)
        h(i, j) = std::numeric_limits<double>::quiet_NaN();  // never read
    return h;
  };
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i)
    d(i) = 1.0 + 3.0 * i;
  const double slack = arbor::qp::QpSettings<double>{}.psd_tolerance;
  bool definite, semidefinite, indefinite;
  {
    const Eigen::Matrix<double, n, n> h = build(d);  // (dynamic Eigen allocates)
    arbor::test::NoAllocScope guard;
    definite = arbor::qp::detail::is_psd(h, slack);
  }
  for (int i = 0; i < n; i += 2)
    d(i) = 0.0;
  semidefinite = arbor::qp::detail::is_psd(build(d), slack);
  d(n - 1) = -1e-3 * (1.0 + 3.0 * (n - 1));
  indefinite = arbor::qp::detail::is_psd(build(d), slack);
  EXPECT_TRUE(definite) << "n = " << n;
  EXPECT_TRUE(semidefinite) << "n = " << n;
  EXPECT_FALSE(indefinite) << "n = " << n;
}

TEST(QpDense, ConvexityCheckOnOddSizesReadsTheUpperTriangle) {
  std::mt19937 rng(3);
  check_convexity_check<1>(rng);
  check_convexity_check<3>(rng);
  check_convexity_check<7>(rng);
  check_convexity_check<13>(rng);
  check_convexity_check<14>(rng);
  check_convexity_check<24>(rng);
}

}  // namespace
