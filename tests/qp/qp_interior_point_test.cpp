// The interior-point cold start (qp/ocp_interior_point.hpp): on random OCP QPs, strictly convex
// and semidefinite (the other sizes, odd ones, float and every instruction set: the QP matrix,
// qp_matrix.hpp, solves each of its problems this way too), and the Kinova-sized benchmark problem,
// the interior point converges (its objective that of the KKT point, its iterate the minimiser
// when the problem is strictly convex; KKT residuals by the tests' own reference code,
// qp_reference.cpp), and the crossover makes the active-set solver end at a KKT point equal to the
// one of its own cold start, in fewer iterations; equalities other than x_0 are refused and
// cold_solve() then starts the active set cold. Double and float; allocation checking on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "alloc_guard.hpp"
#include "arbor/qp/ocp_interior_point.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "kinova_qp.hpp"
#include "qp_reference.hpp"

namespace {
using arbor::qp::IpmStatus;
using arbor::qp::OcpInteriorPoint;
using arbor::qp::OcpQp;
using arbor::qp::OcpQpSolver;
using arbor::qp::QpStatus;
namespace t = arbor::qp::test;

template <int N, int NX, int NU, int NG, int NGN>
void check_random(unsigned seed0, int count, bool strict) {
  using Qp = OcpQp<double, N, NX, NU, NG, NGN>;
  static Qp qp;
  static OcpQpSolver<Qp> cold, crossed;
  static OcpInteriorPoint<Qp> ipm;
  t::RandomOcpOptions opt;
  opt.strictly_convex = strict;
  if (!strict)
    opt.inf_fraction = 0.0;  // keep zero-curvature directions bounded
  int it_cold = 0, it_crossed = 0, it_ipm = 0;
  for (int c = 0; c < count; ++c) {
    std::mt19937 rng(seed0 + unsigned(c));
    t::random_ocp(qp, rng, opt);
    const t::RefQp ref = t::to_ref(qp);
    QpStatus s1, s2, su1, su2;
    IpmStatus si;
    {
      arbor::test::NoAllocScope guard;
      su1 = cold.setup(qp);
      cold.cold_start();
      s1 = cold.solve();
      su2 = crossed.setup(qp);
      si = ipm.solve(qp);
      ipm.warm_start(crossed);
      s2 = crossed.solve();
    }
    SCOPED_TRACE(::testing::Message()
                 << "N=" << N << " nx=" << NX << " nu=" << NU << " ng=" << NG << " ngn=" << NGN
                 << " seed=" << seed0 + unsigned(c) << (strict ? " strict" : " semidefinite"));
    ASSERT_EQ(su1, QpStatus::accepted);
    ASSERT_EQ(su2, QpStatus::accepted);
    EXPECT_EQ(si, IpmStatus::converged) << to_string(si) << " after " << ipm.info().iterations;
    EXPECT_EQ(s1, QpStatus::solved);
    EXPECT_EQ(s2, QpStatus::solved);
    const t::Kkt kd = t::kkt_residuals(ref, cold.x(), cold.lam_x(), cold.lam_a());
    EXPECT_LE(kd.primal, 1e-7 * kd.pscale);
    EXPECT_LE(kd.dual, 1e-7 * kd.dscale);
    const t::Kkt k2 = t::kkt_residuals(ref, crossed.x(), crossed.lam_x(), crossed.lam_a());
    EXPECT_LE(k2.primal, 1e-7 * k2.pscale);
    EXPECT_LE(k2.dual, 1e-7 * k2.dscale);
    EXPECT_LE(k2.complementarity, 1e-7 * k2.pscale);
    // the interior point's own iterate: near the optimum (objective; the minimiser when unique)
    const Eigen::VectorXd xi = ipm.x();
    const double fi = 0.5 * xi.dot(ref.H * xi) + ref.g.dot(xi);
    EXPECT_NEAR(fi, kd.objective, 1e-5 * (1 + std::abs(kd.objective)));
    EXPECT_NEAR(k2.objective, kd.objective, 1e-7 * (1 + std::abs(kd.objective)));
    if (strict) {
      EXPECT_LE((xi - cold.x()).cwiseAbs().maxCoeff(), 1e-5 * kd.pscale);
      EXPECT_LE((crossed.x() - cold.x()).cwiseAbs().maxCoeff(), 1e-6 * kd.pscale);
    }
    it_cold += cold.info().iterations;
    it_crossed += crossed.info().iterations;
    it_ipm += ipm.info().iterations;
  }
  std::printf(
      "N=%d nx=%d nu=%d ng=%d ngn=%d %s: %d problems, active-set iterations cold %d, "
      "after the crossover %d (+ %d interior-point iterations)\n",
      N, NX, NU, NG, NGN, strict ? "strict" : "semidefinite", count, it_cold, it_crossed, it_ipm);
  // the point of the crossover: far fewer active-set iterations than a cold start
  EXPECT_LT(it_crossed, it_cold);
}

TEST(QpInteriorPoint, RandomProblemsStrictlyConvexAndSemidefinite) {
  check_random<8, 4, 2, 1, 1>(100, 20, true);
  check_random<8, 4, 2, 1, 1>(200, 20, false);
}

template <typename Scalar, int NG>
void check_kinova() {
  using Qp = arbor::bench::KinovaQp<Scalar, NG>;
  static Qp qp;
  static OcpQpSolver<Qp> cold, crossed;
  static OcpInteriorPoint<Qp> ipm;
  arbor::bench::make_kinova_qp(qp, 1);
  arbor::qp::QpSettings<Scalar> s;
  s.max_iter = 1000;
  QpStatus s1, s2;
  IpmStatus si;
  {
    arbor::test::NoAllocScope guard;
    (void)cold.setup(qp, s);
    cold.cold_start();
    s1 = cold.solve();
    (void)crossed.setup(qp, s);
    si = ipm.solve(qp);
    ipm.warm_start(crossed);
    s2 = crossed.solve();
  }
  EXPECT_EQ(s1, QpStatus::solved);
  EXPECT_EQ(s2, QpStatus::solved);
  EXPECT_TRUE(si == IpmStatus::converged) << to_string(si);
  // s has no cost of its own (bench/qp/kinova_qp.hpp): the minimiser is not unique; the optimal
  // value is, and the crossed solution is a KKT point by the reference code's residuals
  const t::RefQp ref = t::to_ref(qp);
  const Eigen::VectorXd xc = cold.x().template cast<double>(),
                        x2 = crossed.x().template cast<double>();
  const t::Kkt kc = t::kkt_residuals(ref, xc, cold.lam_x().template cast<double>(),
                                     cold.lam_a().template cast<double>());
  const t::Kkt k2 = t::kkt_residuals(ref, x2, crossed.lam_x().template cast<double>(),
                                     crossed.lam_a().template cast<double>());
  const double tol = std::is_same_v<Scalar, float> ? 1e-4 : 1e-7;
  EXPECT_LE(k2.primal, tol * k2.pscale);
  EXPECT_LE(k2.dual, tol * k2.dscale);
  EXPECT_LE(k2.complementarity, tol * k2.pscale);
  EXPECT_NEAR(k2.objective, kc.objective, 10 * tol * (1 + std::abs(kc.objective)));
  const double dx = (xc - x2).cwiseAbs().maxCoeff();
  std::printf(
      "Kinova-sized QP, NG = %d, %s: cold %d active-set iterations; interior point %d "
      "iterations (%d guessed active), then %d active-set iterations; |x - x_cold| %.2e\n",
      NG, std::is_same_v<Scalar, float> ? "float" : "double", cold.info().iterations,
      ipm.info().iterations, ipm.info().guessed_active, crossed.info().iterations, dx);
  EXPECT_LT(crossed.info().iterations, cold.info().iterations / 4);
}

TEST(QpInteriorPoint, KinovaSizedProblemDouble) {
  check_kinova<double, 1>();
  check_kinova<double, 8>();
}

TEST(QpInteriorPoint, KinovaSizedProblemFloat) {
  check_kinova<float, 1>();
}

TEST(QpInteriorPoint, OtherEqualitiesAreRefusedAndTheActiveSetStartsCold) {
  using Qp = OcpQp<double, 8, 4, 2, 1, 1>;
  static Qp qp;
  static OcpQpSolver<Qp> solver;
  static OcpInteriorPoint<Qp> ipm;
  std::mt19937 rng(7);
  t::random_ocp(qp, rng);
  ASSERT_EQ(solver.setup(qp), QpStatus::accepted);
  ASSERT_EQ(solver.solve(), QpStatus::solved);
  const int iu = Qp::input_offset(3) + 1;
  const double u = solver.x()[iu];  // an input fixed at its optimal value: an equality
  qp.stage[3].lbu[1] = qp.stage[3].ubu[1] = u;
  ASSERT_EQ(solver.setup(qp), QpStatus::accepted);
  EXPECT_EQ(ipm.solve(qp), IpmStatus::unsupported);
  const QpStatus st = arbor::qp::cold_solve(solver, ipm, qp);
  EXPECT_EQ(st, QpStatus::solved);
  EXPECT_EQ(solver.x()[iu], u);
  qp.stage[3].ubu[1] = 1;  // back to an inequality; a path row made an equality instead
  qp.stage[2].lg[0] = qp.stage[2].ug[0];
  EXPECT_EQ(ipm.solve(qp), IpmStatus::unsupported);
}

}  // namespace
