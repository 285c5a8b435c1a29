// OcpQpSolver::feedback_gain (issue 59 item 1): the local feedback gain du_k / dx_k on the final
// working set, against two computations written only for this test:
//   - a condensed dense one: the states x_{k+1..N} eliminated through the dynamics, the Hessian
//     of the stages k..N in (x_k, u_k..u_{N-1}) formed as T' H T, the inputs on a bound of the
//     working set removed, gain = -(H_FF)^-1 H_Fx on the free ones (zero rows elsewhere); the
//     working set's state bounds and path rows as the solver holds them (the documented
//     meaning): weights w = 1 / reg_dual and w / |a|^2, delta = reg_primal on every diagonal;
//     and, in double without state bounds or rows, without any regularisation (the plain
//     equality-constrained LQR gain, tolerance ~ reg_primal);
//   - finite differences through the public API only (double): x_0 moved by h e_c, the QP solved
//     again from the solution, (u_0(x_0 + h e_c) - u_0(x_0)) / h = gain e_c while the working set
//     stays (checked through the multipliers' signs).
// Random OCPs with N, NX, NU in 1, 3, 7, 13; input bounds active at stage 0; state bounds and path
// rows active; double and float. The no-gain cases: before a solve, after update().
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "alloc_guard.hpp"
#include "arbor/qp/ocp_qp_solver.hpp"

namespace {
using arbor::qp::OcpQp;
using arbor::qp::OcpQpSolver;
using arbor::qp::QpStatus;

enum class Kind { inputs, states, rows };

template <typename Scalar, int N, int NX, int NU, int NG>
struct Case {
  using Qp = OcpQp<Scalar, N, NX, NU, NG, 0>;
  Qp qp;

  /// Random strictly convex stages; input bounds tight enough that some are active (inputs),
  /// a state bound on x(0) of stages 1..N (states), or a path row per stage (rows) active.
  Case(unsigned seed, Kind kind) {
    std::mt19937 gen(seed);
    std::normal_distribution<double> nd(0.0, 1.0);
    const auto rnd = [&](int r, int c) {
      Eigen::MatrixXd m(r, c);
      for (int i = 0; i < r; ++i)
        for (int j = 0; j < c; ++j)
          m(i, j) = nd(gen);
      return m;
    };
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (int k = 0; k < N; ++k) {
      auto& s = qp.stage[k];
      const Eigen::MatrixXd g = rnd(NX + NU, NX + NU);
      Eigen::MatrixXd h = g * g.transpose() / double(NX + NU);
      h.diagonal().array() += 0.2;
      s.Q = h.topLeftCorner(NX, NX).template cast<Scalar>();
      s.S = h.bottomLeftCorner(NU, NX).template cast<Scalar>();
      s.R = h.bottomRightCorner(NU, NU).template cast<Scalar>();
      s.A = (Eigen::MatrixXd::Identity(NX, NX) + 0.3 / std::sqrt(double(NX)) * rnd(NX, NX))
                .template cast<Scalar>();
      s.B = (0.5 * rnd(NX, NU)).template cast<Scalar>();
      s.q = rnd(NX, 1).template cast<Scalar>();
      s.r = (kind == Kind::inputs ? 3.0 : 1.0) * rnd(NU, 1).template cast<Scalar>();
      s.b = (0.1 * rnd(NX, 1)).template cast<Scalar>();
      s.lbx.setConstant(Scalar(-inf));
      s.ubx.setConstant(Scalar(inf));
      const Scalar ub = kind == Kind::inputs ? Scalar(1) : Scalar(inf);
      s.lbu.setConstant(-ub);
      s.ubu.setConstant(ub);
      if (kind == Kind::states && k >= 1) {
        s.lbx(0) = Scalar(-0.2);
        s.ubx(0) = Scalar(0.2);
      }
      s.C = rnd(NG, NX).template cast<Scalar>();
      s.D = rnd(NG, NU).template cast<Scalar>();
      s.lg.setConstant(kind == Kind::rows ? Scalar(-0.3) : Scalar(-inf));
      s.ug.setConstant(kind == Kind::rows ? Scalar(0.3) : Scalar(inf));
    }
    auto& t = qp.terminal;
    const Eigen::MatrixXd g = rnd(NX, NX);
    Eigen::MatrixXd h = g * g.transpose() / double(NX);
    h.diagonal().array() += 0.2;
    t.Q = h.template cast<Scalar>();
    t.q = rnd(NX, 1).template cast<Scalar>();
    t.lbx.setConstant(Scalar(-inf));
    t.ubx.setConstant(Scalar(inf));
    if (kind == Kind::states) {
      t.lbx(0) = Scalar(-0.2);
      t.ubx(0) = Scalar(0.2);
    }
    const Eigen::VectorXd x0 = 1.5 * rnd(NX, 1);
    qp.stage[0].lbx = x0.template cast<Scalar>();
    qp.stage[0].ubx = qp.stage[0].lbx;
  }

  /// The dense gain of stage k: inputs with a nonzero bound multiplier (the working set) fixed,
  /// state bounds of stages > k and path rows with a nonzero multiplier as the weights w and
  /// w / |a|^2, delta on every diagonal (delta = 0, w = 0: the unregularised LQR gain).
  Eigen::MatrixXd reference(int k, const Eigen::VectorXd& lam_x, const Eigen::VectorXd& lam_a,
                            double delta, double w) const {
    const int m = (N - k) * NU;       // u_k..u_{N-1}
    const int nz = (N - k + 1) * NX;  // x_k..x_N
    // z = [x_k..x_N; u_k..u_{N-1}] = T [x_k; u]
    Eigen::MatrixXd t = Eigen::MatrixXd::Zero(nz + m, NX + m);
    t.topLeftCorner(NX, NX).setIdentity();
    t.block(nz, NX, m, m).setIdentity();
    for (int j = k; j < N; ++j) {
      const auto& s = qp.stage[j];
      const int r = (j - k) * NX, ru = nz + (j - k) * NU;
      t.middleRows(r + NX, NX) = s.A.template cast<double>() * t.middleRows(r, NX) +
                                 s.B.template cast<double>() * t.middleRows(ru, NU);
    }
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(nz + m, nz + m);
    for (int j = k; j < N; ++j) {
      const auto& s = qp.stage[j];
      const int r = (j - k) * NX, ru = nz + (j - k) * NU;
      h.block(r, r, NX, NX) = s.Q.template cast<double>();
      h.block(ru, ru, NU, NU) = s.R.template cast<double>();
      h.block(ru, r, NU, NX) = s.S.template cast<double>();
      h.block(r, ru, NX, NU) = s.S.transpose().template cast<double>();
      for (int i = 0; i < NX; ++i) {
        if (j > k && lam_x(Qp::state_offset(j) + i) != 0)
          h(r + i, r + i) += w;
      }
      if constexpr (NG > 0) {
        for (int g = 0; g < NG; ++g) {
          if (lam_a(Qp::constraint_offset(j) + g) == 0)
            continue;
          Eigen::VectorXd a = Eigen::VectorXd::Zero(nz + m);
          a.segment(r, NX) = s.C.row(g).transpose().template cast<double>();
          a.segment(ru, NU) = s.D.row(g).transpose().template cast<double>();
          h += w / a.squaredNorm() * a * a.transpose();
        }
      }
    }
    const int rn = (N - k) * NX;
    h.block(rn, rn, NX, NX) = qp.terminal.Q.template cast<double>();
    for (int i = 0; i < NX; ++i) {
      if (lam_x(Qp::state_offset(N) + i) != 0)
        h(rn + i, rn + i) += w;
    }
    h.diagonal().array() += delta;
    const Eigen::MatrixXd hc = t.transpose() * h * t;  // in (x_k, u)
    // stage k's free inputs and all later inputs that are not on a bound
    std::vector<int> free;
    for (int j = k; j < N; ++j)
      for (int i = 0; i < NU; ++i)
        if (lam_x(Qp::input_offset(j) + i) == 0)
          free.push_back((j - k) * NU + i);
    const int nf = static_cast<int>(free.size());
    Eigen::MatrixXd hff(nf, nf), hfx(nf, NX);
    for (int a = 0; a < nf; ++a) {
      hfx.row(a) = hc.block(NX + free[a], 0, 1, NX);
      for (int b = 0; b < nf; ++b)
        hff(a, b) = hc(NX + free[a], NX + free[b]);
    }
    const Eigen::MatrixXd kf = -hff.ldlt().solve(hfx);
    Eigen::MatrixXd gain = Eigen::MatrixXd::Zero(NU, NX);
    for (int a = 0; a < nf; ++a)
      if (free[a] < NU)
        gain.row(free[a]) = kf.row(a);
    return gain;
  }
};

struct Counts {
  int cases = 0;
  int fixed_rows = 0;  ///< stage-0 gain rows of inputs on a bound (checked zero)
  int state_bounds = 0;
  int path_rows = 0;
  int fd_columns = 0;  ///< finite-difference columns checked (working set unchanged)
};

template <typename Scalar, int N, int NX, int NU, int NG>
void check(unsigned seed, Kind kind, Counts& counts) {
  using C = Case<Scalar, N, NX, NU, NG>;
  using Solver = OcpQpSolver<typename C::Qp>;
  SCOPED_TRACE(::testing::Message()
               << "N " << N << " NX " << NX << " NU " << NU << " NG " << NG << " seed " << seed
               << " kind " << int(kind) << (sizeof(Scalar) == 4 ? " float" : " double"));
  const auto c = std::make_unique<C>(seed, kind);
  const auto solver = std::make_unique<Solver>();
  Eigen::Matrix<Scalar, NU, NX> gain;
  ASSERT_EQ(solver->setup(c->qp), QpStatus::accepted);
  EXPECT_FALSE(solver->feedback_gain(0, gain));  // no solve yet: no factor
  const QpStatus st = solver->solve();
  if (st != QpStatus::solved)
    return;  // (a random infeasible or hard case: another seed checks)
  ASSERT_EQ(solver->info().regularization_bumps, 0);
  ++counts.cases;
  const Eigen::VectorXd lam_x = solver->lam_x().template cast<double>();
  const Eigen::VectorXd lam_a = solver->lam_a().template cast<double>();
  for (int k = 1; k <= N; ++k)
    for (int i = 0; i < NX; ++i)
      counts.state_bounds += lam_x(C::Qp::state_offset(k) + i) != 0;
  for (int k = 0; k < N; ++k)
    for (int g = 0; g < NG; ++g)
      counts.path_rows += lam_a(C::Qp::constraint_offset(k) + g) != 0;
  const double delta = solver->settings().reg_primal, w = 1.0 / solver->settings().reg_dual;
  const bool dbl = sizeof(Scalar) == 8;
  for (int k : {0, 1, N - 1}) {
    if (k >= N)
      continue;
    {
      arbor::test::NoAllocScope guard;
      ASSERT_TRUE(solver->feedback_gain(k, gain));
    }
    const Eigen::MatrixXd got = gain.template cast<double>();
    const Eigen::MatrixXd ref = c->reference(k, lam_x, lam_a, delta, w);
    const double scale = 1 + ref.cwiseAbs().maxCoeff();
    EXPECT_LE((got - ref).cwiseAbs().maxCoeff(), (dbl ? 1e-9 : 2e-3) * scale)
        << "stage " << k << "\ngot\n"
        << got << "\nref\n"
        << ref;
    for (int i = 0; i < NU; ++i) {
      if (lam_x(C::Qp::input_offset(k) + i) != 0) {
        EXPECT_EQ(got.row(i).cwiseAbs().maxCoeff(), 0.0) << "stage " << k << " input " << i;
        counts.fixed_rows += k == 0;
      }
    }
    if (dbl && kind == Kind::inputs) {  // the plain LQR gain of the working set, delta -> 0
      const Eigen::MatrixXd plain = c->reference(k, lam_x, lam_a, 0.0, 0.0);
      EXPECT_LE((got - plain).cwiseAbs().maxCoeff(), 1e-6 * (1 + plain.cwiseAbs().maxCoeff()))
          << "stage " << k;
    }
  }
  if constexpr (sizeof(Scalar) == 8) {
    // finite differences through the public API: x_0 moved, solved again from the solution
    ASSERT_TRUE(solver->feedback_gain(0, gain));
    const Eigen::MatrixXd k0 = gain;
    solver->settings().tol_primal = 1e-12;
    solver->settings().tol_dual = 1e-12;
    solver->settings().tol_comp = 1e-12;
    ASSERT_EQ(solver->solve(), QpStatus::solved);  // the base point to the same accuracy
    const Eigen::VectorXd u0 = solver->input(0);
    const auto x = solver->x();
    const auto lx = solver->lam_x();
    const auto la = solver->lam_a();
    const double h = 1e-4;
    const auto x0 = c->qp.stage[0].lbx;
    for (int col = 0; col < NX; ++col) {
      c->qp.stage[0].lbx = x0;
      c->qp.stage[0].lbx(col) += h;
      c->qp.stage[0].ubx = c->qp.stage[0].lbx;
      ASSERT_EQ(solver->update(), QpStatus::accepted);
      EXPECT_FALSE(solver->feedback_gain(0, gain));  // new data: no factor until the solve
      solver->set_warm_start(x, lx, la);
      ASSERT_EQ(solver->solve(), QpStatus::solved);
      bool same = true;  // the working set of the first solve (multipliers' signs)
      for (int i = 0; i < solver->lam_x().size(); ++i)
        same &= (solver->lam_x()(i) > 0) == (lam_x(i) > 0) &&
                (solver->lam_x()(i) < 0) == (lam_x(i) < 0);
      for (int i = 0; i < solver->lam_a().size(); ++i)
        same &= (solver->lam_a()(i) != 0) == (lam_a(i) != 0) ||
                i % (NX + NG) < NX;  // (the dynamics rows: always)
      if (!same)
        continue;
      ++counts.fd_columns;
      const Eigen::VectorXd du = (solver->input(0) - u0) / h;
      // the gain holds the working set's state bounds and rows by the weights (1 / w = 1e-6)
      EXPECT_LE((du - k0.col(col)).cwiseAbs().maxCoeff(),
                (kind == Kind::inputs ? 1e-6 : 1e-3) * (1 + k0.cwiseAbs().maxCoeff()))
          << "column " << col << "\nfd " << du.transpose() << "\ngain " << k0.col(col).transpose();
    }
  }
}

template <typename Scalar>
void run_all(Counts& ci, Counts& cs, Counts& cr) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    check<Scalar, 1, 1, 1, 0>(seed, Kind::inputs, ci);
    check<Scalar, 3, 3, 1, 0>(seed, Kind::inputs, ci);
    check<Scalar, 7, 3, 3, 0>(seed, Kind::inputs, ci);
    check<Scalar, 13, 7, 3, 0>(seed, Kind::inputs, ci);
    check<Scalar, 3, 13, 7, 0>(seed, Kind::inputs, ci);
    check<Scalar, 7, 1, 3, 0>(seed, Kind::inputs, ci);
    check<Scalar, 7, 3, 1, 0>(seed, Kind::states, cs);
    check<Scalar, 3, 7, 3, 0>(seed, Kind::states, cs);
    check<Scalar, 13, 3, 3, 0>(seed, Kind::states, cs);
    check<Scalar, 7, 3, 3, 1>(seed, Kind::rows, cr);
    check<Scalar, 3, 7, 3, 1>(seed, Kind::rows, cr);
    check<Scalar, 1, 3, 1, 1>(seed, Kind::rows, cr);
  }
}

TEST(FeedbackGain, DoubleMatchesDenseAndFiniteDifferences) {
  Counts ci, cs, cr;
  run_all<double>(ci, cs, cr);
  // the cases were not vacuous: most solved, bounds and rows active
  EXPECT_GE(ci.cases, 30);
  EXPECT_GE(ci.fixed_rows, 10);
  EXPECT_GE(cs.cases, 12);
  EXPECT_GE(cs.state_bounds, 12);
  EXPECT_GE(cr.cases, 12);
  EXPECT_GE(cr.path_rows, 12);
  EXPECT_GE(ci.fd_columns + cs.fd_columns + cr.fd_columns, 100);
}

TEST(FeedbackGain, FloatMatchesDense) {
  Counts ci, cs, cr;
  run_all<float>(ci, cs, cr);
  EXPECT_GE(ci.cases, 30);
  EXPECT_GE(ci.fixed_rows, 10);
  EXPECT_GE(cs.cases, 12);
  EXPECT_GE(cs.state_bounds, 12);
  EXPECT_GE(cr.cases, 12);
  EXPECT_GE(cr.path_rows, 12);
}

}  // namespace
