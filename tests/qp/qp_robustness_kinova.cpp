// Robustness of the active-set core (issue 15), part of qp_robustness_test: the float cold solve
// of the Kinova-sized benchmark problem (bench/qp/kinova_qp.hpp, nominal, max_iter 1000) that
// used to stall at the iteration cap, and the anti-cycling rule that keeps it from cycling when
// the tolerances are below float's round-off floor. The solutions are checked in double against
// the KKT conditions on the same (float) data (qp_reference.hpp).
#include <gtest/gtest.h>

#include <algorithm>

#include "alloc_guard.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "kinova_qp.hpp"
#include "qp_reference.hpp"
#include "qp_robustness.hpp"
#include "status_names.hpp"

namespace arbor::qp {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace {
using arbor::qp::OcpQpSolver;
using arbor::qp::QpSettings;
using arbor::qp::QpStatus;
namespace t = arbor::qp::test;

using t::cold_solve;

using KinovaF = arbor::bench::KinovaQp<float, 1>;

/// KKT residuals of the float solution, in double on the float data.
void expect_float_kkt(const KinovaF& qp, const OcpQpSolver<KinovaF>& s) {
  const t::RefQp ref = t::to_ref(qp);
  const t::Kkt k = t::kkt_residuals(ref, s.x().cast<double>(), s.lam_x().cast<double>(),
                                    s.lam_a().cast<double>());
  EXPECT_LE(k.primal, 2e-3 * k.pscale);
  EXPECT_LE(k.dual, 2e-3 * k.dscale);
  EXPECT_LE(k.complementarity, 2e-3 * k.pscale);
}

TEST(QpRobustness, FloatKinovaColdSolveNoLongerStalls) {
  // Formerly: 1000 iterations (the cap), 600 working-set changes, primal residual 7.3e-4; with
  // tolerances 1e-6 (below float's round-off floor on this problem) the same cycle of drops and
  // re-additions of three bounds runs to the cap unless the anti-cycling rule refuses the
  // repeated drop.
  static KinovaF nominal, perturbed;
  static OcpQpSolver<KinovaF> s;
  arbor::bench::make_kinova_qp(nominal, 1);
  arbor::bench::make_kinova_qp(perturbed, 1, 1e-3, 0.01);
  QpSettings<float> set;
  set.max_iter = 1000;
  ASSERT_EQ(cold_solve(s, nominal, set), QpStatus::solved);
  EXPECT_LE(s.info().iterations, 300);
  expect_float_kkt(nominal, s);
  QpStatus warm;
  {
    arbor::test::NoAllocScope guard;
    ASSERT_EQ(s.setup(perturbed, set), QpStatus::accepted);
    warm = s.solve();
  }
  EXPECT_EQ(warm, QpStatus::solved);
  EXPECT_LE(s.info().iterations, 5);
  expect_float_kkt(perturbed, s);

  QpSettings<float> tight = set;
  tight.tol_primal = tight.tol_dual = tight.tol_comp = 1e-6f;
  const QpStatus st = cold_solve(s, nominal, tight);
  EXPECT_TRUE(st == QpStatus::solved || st == QpStatus::stalled) << st;
  EXPECT_LE(s.info().iterations, 400);
  expect_float_kkt(nominal, s);
  // below any reachable accuracy: a clear status, the best iterate and its own residuals
  tight.tol_primal = tight.tol_dual = tight.tol_comp = 1e-12f;
  EXPECT_EQ(cold_solve(s, nominal, tight), QpStatus::stalled);
  EXPECT_LT(s.info().iterations, 1000);
  expect_float_kkt(nominal, s);
  const t::Kkt k = t::kkt_residuals(t::to_ref(nominal), s.x().cast<double>(),
                                    s.lam_x().cast<double>(), s.lam_a().cast<double>());
  EXPECT_NEAR(k.primal, std::max(0.0, double(s.info().primal_residual)), 1e-5 * k.pscale);
}

}  // namespace
