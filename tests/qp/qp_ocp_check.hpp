// Shared check of the OCP tests: solve a random OcpQp with the structured solver (OcpQpSolver,
// the Riccati backend) and the dense solver (inside an allocation guard) and compare them with the KKT conditions, recomputed with dynamic Eigen, and
// optionally with the exhaustive active-set enumeration.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "alloc_guard.hpp"
#include "arbor/qp/dense_qp_solver.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "qp_reference.hpp"
#include "status_names.hpp"

namespace arbor::qp {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace arbor::qp::test {

/// Kind of random problem.
enum class Convexity { strict, merely, lp };

/// Checks one structured solve (status, KKT conditions, objective and, for strictly convex
/// problems, the point) against the dense solution and, when given, the enumeration.
template <typename Solver, typename Dense>
void expect_matches(const char* backend, const Solver& solver, QpStatus su, QpStatus st,
                    const RefQp& ref, const Dense& dense, const Kkt& kd, bool strict,
                    const EnumResult* e) {
  SCOPED_TRACE(backend);
  ASSERT_EQ(su, QpStatus::accepted);
  EXPECT_EQ(st, QpStatus::solved) << to_string(st) << " iters " << solver.info().iterations;
  const Kkt k = kkt_residuals(ref, solver.x(), solver.lam_x(), solver.lam_a());
  EXPECT_LE(k.primal, 1e-7 * k.pscale);
  EXPECT_LE(k.dual, 1e-7 * k.dscale);
  EXPECT_LE(k.complementarity, 1e-7 * k.pscale);
  const double ftol = objective_tolerance(k, solver.x(), solver.lam_x(), solver.lam_a(), 1e-9) +
                      objective_tolerance(kd, dense.x(), dense.lam_x(), dense.lam_a(), 1e-9);
  EXPECT_NEAR(k.objective, kd.objective, ftol);
  if (strict) {
    EXPECT_LE((solver.x() - dense.x()).cwiseAbs().maxCoeff(), 1e-6 * k.pscale);
  }
  if (e != nullptr) {
    EXPECT_NEAR(k.objective, e->objective,
                objective_tolerance(k, solver.x(), solver.lam_x(), solver.lam_a(), 1e-8));
    if (strict) {
      EXPECT_LE((solver.x() - e->x).cwiseAbs().maxCoeff(), 1e-6 * k.pscale);
    }
  }
}

/// count random problems of one kind and size, each solved by the OCP solver and by the dense
/// solver (and, with enumerate, by enumeration).
template <int N, int NX, int NU, int NG, int NGN>
void check_random(unsigned seed0, int count, Convexity kind, bool enumerate) {
  const bool strict = kind == Convexity::strict;
  using Qp = OcpQp<double, N, NX, NU, NG, NGN>;
  static Qp qp;
  static OcpQpSolver<Qp> solver;
  static DenseQpProblem<double, Qp::nv, Qp::na> dp;
  static DenseQpSolver<double, Qp::nv, Qp::na> dense;
  RandomOcpOptions opt;
  opt.strictly_convex = strict;
  opt.lp = kind == Convexity::lp;
  if (!strict)
    opt.inf_fraction = 0.0;  // keep zero-curvature directions bounded
  for (int c = 0; c < count; ++c) {
    std::mt19937 rng(seed0 + static_cast<unsigned>(c));
    random_ocp(qp, rng, opt);
    const RefQp ref = to_ref(qp);
    to_dense(ref, dp);
    QpStatus st, sd, su, sdu;
    {
      arbor::test::NoAllocScope guard;
      su = solver.setup(qp);
      solver.cold_start();
      st = solver.solve();
      sdu = dense.setup(dp);
      dense.cold_start();
      sd = dense.solve();
    }
    SCOPED_TRACE(::testing::Message() << "N=" << N << " nx=" << NX << " nu=" << NU << " ng=" << NG
                                      << " ngn=" << NGN << " seed=" << seed0 + c);
    ASSERT_EQ(sdu, QpStatus::accepted);
    EXPECT_EQ(sd, QpStatus::solved) << to_string(sd) << " iters " << dense.info().iterations;
    const Kkt kd = kkt_residuals(ref, dense.x(), dense.lam_x(), dense.lam_a());
    EXPECT_LE(kd.primal, 1e-7 * kd.pscale);
    EXPECT_LE(kd.dual, 1e-7 * kd.dscale);
    EXPECT_LE(kd.complementarity, 1e-7 * kd.pscale);
    EnumResult e;
    if (enumerate) {
      e = enumerate_active_sets(ref);
      ASSERT_TRUE(e.found);
    }
    const EnumResult* pe = enumerate ? &e : nullptr;
    expect_matches("OCP solver (Riccati backend)", solver, su, st, ref, dense, kd, strict, pe);
  }
}

}  // namespace arbor::qp::test
