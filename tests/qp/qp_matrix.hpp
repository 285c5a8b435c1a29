// The QP size matrix (issue 35): random, strictly convex, feasible-by-construction OcpQps of many
// sizes, solved by the OCP solver (default Riccati backend) in double or float and checked
//   - against the dense solver (DenseQpSolver: the same active-set logic on a dense Cholesky, a
//     different linear algebra) on the same problem in double: same point (unique minimiser);
//   - by KKT residuals recomputed here from the OcpQp's stages with plain loops in double
//     (stationarity, feasibility, complementarity, multiplier signs), independent of both solvers.
// Above kDenseMax variables the dense solver is left out and the KKT check decides alone.
// Static memory only (portable: host, AArch64, Cortex-M7, Cortex-M4F); no files, no heap.
// The seed of every case is printed; ARBOR_SEED=<s> in the environment (hosted builds) runs only
// that seed, so a failing case is reproduced from the command line.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "arbor/qp/dense_qp_solver.hpp"
#include "arbor/qp/ocp_interior_point.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"
#include "arbor_test.hpp"
#include "qp_random_static.hpp"
#include "status_names.hpp"
#include "test_log.hpp"

namespace arbor::qp {
using ::arbor::test::status_names::operator<<;  // failure messages print status names
}

namespace qp_matrix {

using arbor::qp::QpStatus;

/// The equivalent dense QP (the flat layout of problem.hpp), written here from the stages, in the
/// leading nv variables and na rows of a dense problem of fixed size (one dense solver type serves
/// every size, compiled once): the remaining variables are free and decoupled (H = I, g = 0, no
/// bounds: zero at the optimum), the remaining rows zero and unbounded (never active).
template <class Qp, class Dense>
void to_dense(const Qp& q, Dense& d) {
  constexpr int N = Qp::horizon, NX = Qp::nx, NU = Qp::nu, NG = Qp::ng, NGN = Qp::ngn;
  d.H.setIdentity();
  d.g.setZero();
  d.A.setZero();
  d.lbx.setConstant(-kInf);
  d.ubx.setConstant(kInf);
  d.lba.setConstant(-kInf);
  d.uba.setConstant(kInf);
  for (int k = 0; k < N; ++k) {
    const auto& s = q.stage[std::size_t(k)];
    const int o = Qp::state_offset(k), ou = Qp::input_offset(k), on = Qp::state_offset(k + 1);
    const int r = Qp::dynamics_offset(k), c = Qp::constraint_offset(k);
    d.H.template block<NX, NX>(o, o) = s.Q;
    d.H.template block<NU, NX>(ou, o) = s.S;
    d.H.template block<NX, NU>(o, ou) = s.S.transpose();
    d.H.template block<NU, NU>(ou, ou) = s.R;
    d.g.template segment<NX>(o) = s.q;
    d.g.template segment<NU>(ou) = s.r;
    d.lbx.template segment<NX>(o) = s.lbx;
    d.ubx.template segment<NX>(o) = s.ubx;
    d.lbx.template segment<NU>(ou) = s.lbu;
    d.ubx.template segment<NU>(ou) = s.ubu;
    d.A.template block<NX, NX>(r, on).setIdentity();
    d.A.template block<NX, NX>(r, o) = -s.A;
    d.A.template block<NX, NU>(r, ou) = -s.B;
    d.lba.template segment<NX>(r) = s.b;
    d.uba.template segment<NX>(r) = s.b;
    d.A.template block<NG, NX>(c, o) = s.C;
    d.A.template block<NG, NU>(c, ou) = s.D;
    d.lba.template segment<NG>(c) = s.lg;
    d.uba.template segment<NG>(c) = s.ug;
  }
  const int o = Qp::state_offset(N), c = Qp::constraint_offset(N);
  d.H.template block<NX, NX>(o, o) = q.terminal.Q;
  d.g.template segment<NX>(o) = q.terminal.q;
  d.lbx.template segment<NX>(o) = q.terminal.lbx;
  d.ubx.template segment<NX>(o) = q.terminal.ubx;
  d.A.template block<NGN, NX>(c, o) = q.terminal.C;
  d.lba.template segment<NGN>(c) = q.terminal.lg;
  d.uba.template segment<NGN>(c) = q.terminal.ug;
}

/// KKT residuals of (x, lam_x, lam_a) (flat layout) for the OcpQp q (double), computed stage by
/// stage here, relative to their scales: stationarity H x + g + lam_x + A' lam_a = 0 with the rows
/// dyn_k = x_{k+1} - A_k x_k - B_k u_k and gen_k = C_k x_k + D_k u_k of problem.hpp; bounds; a
/// positive multiplier only at an upper bound, a negative one only at a lower one
/// (complementarity: min(|lam|, distance), an infinite distance for a wrong sign).
struct Kkt {
  double dual = 0, primal = 0, comp = 0, dscale = 1, pscale = 1;
};
template <class Qp, class V, class W>
Kkt kkt(const Qp& q, const V& x, const V& lx, const W& la) {
  constexpr int N = Qp::horizon, NX = Qp::nx, NU = Qp::nu, NG = Qp::ng, NGN = Qp::ngn;
  using VX = Eigen::Matrix<double, NX, 1>;
  using VU = Eigen::Matrix<double, NU, 1>;
  Kkt k;
  double hmax = 0, gmax = 0, amax = 0, xmax = x.cwiseAbs().maxCoeff(), zmax = 0;
  auto check = [&](double zi, double l, double u, double m) {
    k.primal = std::max(k.primal, std::max(l - zi, zi - u));
    if (m > 0)
      k.comp = std::max(k.comp, std::min(m, std::fabs(u - zi)));
    else if (m < 0)
      k.comp = std::max(k.comp, std::min(-m, std::fabs(zi - l)));
  };
  // per variable: H x, g and lam_x + A' lam_a, accumulated stage by stage
  auto add = [&](double hx, double g, double a) {
    k.dual = std::max(k.dual, std::fabs(hx + g + a));
    hmax = std::max(hmax, std::fabs(hx));
    gmax = std::max(gmax, std::fabs(g));
    amax = std::max(amax, std::fabs(a));
  };
  VX prev_dyn = VX::Zero();  // lam of dyn_{k-1} (its +x_k term)
  for (int k_ = 0; k_ < N; ++k_) {
    const auto& s = q.stage[std::size_t(k_)];
    const int o = Qp::state_offset(k_), ou = Qp::input_offset(k_), on = Qp::state_offset(k_ + 1);
    const int r = Qp::dynamics_offset(k_), c = Qp::constraint_offset(k_);
    const VX xk = x.template segment<NX>(o), xn = x.template segment<NX>(on);
    const VU uk = x.template segment<NU>(ou);
    const VX ld = la.template segment<NX>(r);
    const Eigen::Matrix<double, NG, 1> lg = la.template segment<NG>(c);
    const VX hx = s.Q * xk + s.S.transpose() * uk;
    const VU hu = s.S * xk + s.R * uk;
    const VX ax =
        lx.template segment<NX>(o) + prev_dyn - s.A.transpose() * ld + s.C.transpose() * lg;
    const VU au = lx.template segment<NU>(ou) - s.B.transpose() * ld + s.D.transpose() * lg;
    for (int i = 0; i < NX; ++i) {
      add(hx[i], s.q[i], ax[i]);
      check(xk[i], s.lbx[i], s.ubx[i], lx[o + i]);
    }
    for (int i = 0; i < NU; ++i) {
      add(hu[i], s.r[i], au[i]);
      check(uk[i], s.lbu[i], s.ubu[i], lx[ou + i]);
    }
    const VX dyn = xn - s.A * xk - s.B * uk;
    for (int i = 0; i < NX; ++i) {
      check(dyn[i], s.b[i], s.b[i], ld[i]);
      zmax = std::max(zmax, std::fabs(dyn[i]));
    }
    const Eigen::Matrix<double, NG, 1> g = s.C * xk + s.D * uk;
    for (int i = 0; i < NG; ++i) {
      check(g[i], s.lg[i], s.ug[i], lg[i]);
      zmax = std::max(zmax, std::fabs(g[i]));
    }
    prev_dyn = ld;
  }
  const auto& t = q.terminal;
  const int o = Qp::state_offset(N), c = Qp::constraint_offset(N);
  const VX xN = x.template segment<NX>(o);
  const Eigen::Matrix<double, NGN, 1> lg = la.template segment<NGN>(c);
  const VX hx = t.Q * xN;
  const VX ax = lx.template segment<NX>(o) + prev_dyn + t.C.transpose() * lg;
  for (int i = 0; i < NX; ++i) {
    add(hx[i], t.q[i], ax[i]);
    check(xN[i], t.lbx[i], t.ubx[i], lx[o + i]);
  }
  const Eigen::Matrix<double, NGN, 1> g = t.C * xN;
  for (int i = 0; i < NGN; ++i) {
    check(g[i], t.lg[i], t.ug[i], lg[i]);
    zmax = std::max(zmax, std::fabs(g[i]));
  }
  k.dscale = 1 + std::max({hmax, gmax, amax});
  k.pscale = 1 + std::max(xmax, zmax);
  return k;
}

/// Seeds to run: ARBOR_SEED from the environment (hosted builds) or `count` from seed0.
inline bool seed_selected(std::uint64_t seed) {
#if !defined(ARBOR_BARE_METAL)
  if (const char* e = std::getenv("ARBOR_SEED"))
    return std::strtoull(e, nullptr, 10) == seed;
#endif
  (void)seed;
  return true;
}

/// One size: `count` random problems from seed0, the OCP solver in scalar S against the dense
/// solver in double and the KKT check. Prints one line per size (worst figures and seeds).
/// The dense reference is one type, DenseQpSolver<double, kDenseMax, kDenseRows>, for every size
/// (to_dense pads): one instantiation of the dense solver per unit instead of one per size (at -O1
/// the per-size dense solvers made most of the unit's 7 min of compiler time and 5.7 GB).
/// Sizes with nv above kDenseMax or na above kDenseRows are checked by the KKT conditions alone
/// (strictly convex: they certify the unique minimiser): a dense reference of the crash size
/// (nv = 434) costs ~3.5 GB of compiler memory at -O3, more than Eigen's fixed-size object limit,
/// and seconds per solve.
inline constexpr int kDenseMax = 56;
inline constexpr int kDenseRows = 48;
using DenseProblem = arbor::qp::DenseQpProblem<double, kDenseMax, kDenseRows>;
using DenseSolver = arbor::qp::DenseQpSolver<double, kDenseMax, kDenseRows>;
/// The one dense problem and solver of a unit (static storage: ~100 KB on the targets).
inline DenseProblem& dense_problem() {
  static DenseProblem p;
  return p;
}
inline DenseSolver& dense_solver() {
  static DenseSolver s;
  return s;
}

/// (noinline: each size is called once, and GCC would inline them all into the test's body, one
/// function whose compile time grows faster than its size)
/// Ipm: also solve each problem by the interior-point cold start (qp/ocp_interior_point.hpp);
/// on in the per-instruction-set file, off for the host-only sizes (compile time)
template <class S, int N, int NX, int NU, int NG, int NGN, bool Ipm = true>
[[gnu::noinline]] void check_size(std::uint64_t seed0, int count, const char* isa) {
  using Qd = arbor::qp::OcpQp<double, N, NX, NU, NG, NGN>;
  using Qs = arbor::qp::OcpQp<S, N, NX, NU, NG, NGN>;
  constexpr int NV = Qd::nv, NA = Qd::na;
  static Qd qd;
  static Qs qs;
  constexpr bool with_dense = NV <= kDenseMax && NA <= kDenseRows;
  DenseProblem& dp = dense_problem();
  DenseSolver& dense = dense_solver();
  static arbor::qp::OcpQpSolver<Qs> solver;
  constexpr bool single = sizeof(S) == 4;
  // tolerances: the solver's own (relative 1e-8 / 1e-4) with margin; the point against the
  // dense solution relative to the solution's scale (float: the data's rounding moves it too)
  const double tk = single ? 1e-3 : 1e-7, tx = single ? 2e-2 : 1e-6;
  double worst_x = 0, worst_kkt = 0;
  int iters = 0;
  for (int c = 0; c < count; ++c) {
    const std::uint64_t seed = seed0 + std::uint64_t(c);
    if (!seed_selected(seed))
      continue;
    random_problem(qd, seed);
    cast_problem<S>(qd, qs);
    if constexpr (with_dense)
      to_dense(qd, dp);
    QpStatus su, st, sdu = QpStatus::accepted, sd = QpStatus::solved;
    {
      arbor::test::NoAllocScope guard;
      // a cold start takes one iteration per working-set change: hundreds at N = 20
      arbor::qp::QpSettings<S> settings;
      settings.max_iter = 5000;
      su = solver.setup(qs, settings);
      solver.cold_start();
      st = solver.solve();
      if constexpr (with_dense) {
        sdu = dense.setup(dp);
        dense.cold_start();
        sd = dense.solve();
      }
    }
    arbor::test::log() << "    seed " << seed << ": ocp " << arbor::qp::to_string(st) << " ("
                       << solver.info().iterations << " it)";
    if constexpr (with_dense)
      arbor::test::log() << ", dense " << arbor::qp::to_string(sd) << " ("
                         << dense.info().iterations << " it)";
    arbor::test::log() << "\n";
    ASSERT_EQ(su, QpStatus::accepted) << "seed " << seed;
    ASSERT_EQ(sdu, QpStatus::accepted) << "seed " << seed;
    ASSERT_EQ(sd, QpStatus::solved) << "dense reference, seed " << seed;
    EXPECT_EQ(st, QpStatus::solved) << "seed " << seed << " (reproduce: ARBOR_SEED=" << seed << ")";
    // the OCP solution in the flat layout
    static Eigen::Matrix<double, NV, 1> x, lx;
    static Eigen::Matrix<double, NA, 1> la;
    x = solver.x().template cast<double>();
    lx = solver.lam_x().template cast<double>();
    la = solver.lam_a().template cast<double>();
    const Kkt k = kkt(qd, x, lx, la);
    const double e = std::max({k.dual / k.dscale, k.primal / k.pscale, k.comp / k.pscale});
    EXPECT_LE(e, tk) << "KKT of the OCP solution, seed " << seed << ": dual " << k.dual
                     << " primal " << k.primal << " comp " << k.comp;
    double dx = 0;
    if constexpr (with_dense) {
      static Eigen::Matrix<double, NV, 1> xd, lxd;
      static Eigen::Matrix<double, NA, 1> lad;
      xd = dense.x().template head<NV>();
      lxd = dense.lam_x().template head<NV>();
      lad = dense.lam_a().template head<NA>();
      const Kkt kd = kkt(qd, xd, lxd, lad);
      EXPECT_LE(kd.dual, 1e-7 * kd.dscale) << "dense reference, seed " << seed;
      if constexpr (NV < kDenseMax) {  // the padding's variables at their free optimum, zero
        EXPECT_LE(dense.x().template tail<kDenseMax - NV>().cwiseAbs().maxCoeff(), 1e-9)
            << "dense reference's padding, seed " << seed;
      }
      dx = (x - xd).cwiseAbs().maxCoeff() / (1 + xd.cwiseAbs().maxCoeff());
      EXPECT_LE(dx, tx) << "OCP vs dense solution, seed " << seed;
    }
    worst_x = std::max(worst_x, dx);
    worst_kkt = std::max(worst_kkt, e);
    iters = std::max(iters, solver.info().iterations);
    // the interior-point cold start (qp/ocp_interior_point.hpp) and its crossover: the same
    // (unique: strictly convex) solution as the active set's own cold start
    if constexpr (Ipm) {
      static arbor::qp::OcpInteriorPoint<Qs> ipm;
      QpStatus si;
      const int cold_iterations = solver.info().iterations;
      {
        arbor::test::NoAllocScope guard;
        arbor::qp::QpSettings<S> settings;
        settings.max_iter = 5000;
        su = solver.setup(qs, settings);
        si = arbor::qp::cold_solve(solver, ipm, qs);
      }
      ASSERT_EQ(su, QpStatus::accepted) << "seed " << seed;
      EXPECT_EQ(si, QpStatus::solved) << "interior-point cold start, seed " << seed;
      // float may stop at its round-off floor before tol (precision_limit): still crossed over
      EXPECT_TRUE(arbor::qp::crossover_point(ipm.status()))
          << arbor::qp::to_string(ipm.status()) << ", seed " << seed;
      const double dxi = (solver.x().template cast<double>() - x).cwiseAbs().maxCoeff() /
                         (1 + x.cwiseAbs().maxCoeff());
      EXPECT_LE(dxi, tx) << "interior-point cold start vs the active set's, seed " << seed;
      arbor::test::log() << "    seed " << seed << ": interior point "
                         << arbor::qp::to_string(ipm.status()) << " (" << ipm.info().iterations
                         << " it), then " << solver.info().iterations
                         << " active-set it (cold: " << cold_iterations << "), |dx| " << dxi
                         << "\n";
    }
  }
  arbor::test::log() << "  [" << isa << (single ? " float" : " double") << "] N=" << N
                     << " nx=" << NX << " nu=" << NU << " ng=" << NG << " ngn=" << NGN
                     << " (nv=" << NV << ", na=" << NA << "): " << count << " seeds from " << seed0
                     << ", worst |x - x_dense| " << worst_x << ", worst KKT " << worst_kkt
                     << ", most iterations " << iters << "\n";
}

}  // namespace qp_matrix
