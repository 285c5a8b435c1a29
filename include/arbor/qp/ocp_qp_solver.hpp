// arbor::qp: static-memory active-set solver for the optimal-control QP (problem.hpp).
//
// Active-set logic: active_set.hpp (QRQP-style primal-dual, one change per iteration, ratio test
// with primal blocking constraints and dual break points, warm start from x and lam).
//
// Linear algebra exploiting the stage structure. Each iteration solves with
//   M = H + delta I + A_W' E A_W     (E: regularisation weights, see active_set.hpp)
// where A_W holds the dynamics rows (always active) and the active bounds and stage constraints.
// H is block diagonal, every active bound or stage row touches one stage and a dynamics row
// touches w_k = (x_k, u_k) and x_{k+1}, so M is block tridiagonal with diagonal blocks of size
// NW = NX + NU (NX for the terminal stage) and off-diagonal blocks -[A_k B_k]' E_k that touch
// x_{k+1} only. It is factorized as M = U'U with U block upper bidiagonal:
//   U_kk' U_kk = M_kk - U_{k-1,k}' U_{k-1,k}     (only the x_k x_k corner is corrected)
//   U_{k,k+1} = U_kk^-T M_{k,k+1}                 (NW x NX)
// a block Cholesky that runs forward in k. It is positive definite for any convex problem and any
// working set, so no rank decisions are needed (see active_set.hpp). A working-set change at
// stage k leaves blocks 0..k-1 valid: only stages k..N are refactorized ("updates instead of
// refactorization" at stage granularity; a change near the end of the horizon is cheap).
// Cost: O(N (NX+NU)^3) per factorization, O(N (NX+NU)^2) per solve.
// Memory (scalars): N (NW^2 + NW NX) + NX^2 for the factor, about 11 NV + 8 NA for the
// iterate and workspace, with NV = N NW + NX, NA = N (NX+NG) + NGN; no dense KKT matrix.
// The problem data are referenced, not copied.
//
//   using Qp = OcpQp<double, 16, 16, 8, 1>;
//   static Qp qp;                        // fill the stages
//   static OcpQpSolver<Qp> solver;
//   solver.setup(qp);                    // checks data; keeps the last iterate (warm start)
//   QpStatus st = solver.solve();        // solver.state(k), solver.input(k), solver.info()
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "arbor/qp/active_set.hpp"
#include "arbor/qp/cholesky.hpp"
#include "arbor/qp/dense_qp_solver.hpp"
#include "arbor/qp/problem.hpp"
#include "arbor/qp/settings.hpp"
#include "arbor/qp/status.hpp"

namespace arbor::qp {

namespace detail {

/// Block-tridiagonal Cholesky backend for ActiveSetCore on an OcpQp.
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
struct OcpBackend {
  using Problem = OcpQp<Scalar, N, NX, NU, NG, NGN>;
  static constexpr int NW = NX + NU;
  static constexpr int NV = Problem::nv;
  static constexpr int NA = Problem::na;
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;
  using VecW = Eigen::Matrix<Scalar, NW, 1>;
  using VecX = Eigen::Matrix<Scalar, NX, 1>;
  using MatW = Eigen::Matrix<Scalar, NW, NW>;
  using MatWX = Eigen::Matrix<Scalar, NW, NX>;
  using MatX = Eigen::Matrix<Scalar, NX, NX>;

  const Problem* p = nullptr;  ///< referenced problem
  std::array<MatW, N> u_diag;  ///< U_kk (upper triangle)
  std::array<MatWX, N> u_off;  ///< U_{k,k+1}, columns of x_{k+1}
  MatX u_term;                 ///< U_NN (upper triangle)
  int dirty_from = 0;          ///< first stage whose blocks must be refactorized (N+1: none)

  void hess_mul(const VecV& x, VecV& y) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const int o = k * NW;
      const auto xk = x.template segment<NX>(o);
      const auto uk = x.template segment<NU>(o + NX);
      y.template segment<NX>(o).noalias() = s.Q * xk;
      y.template segment<NX>(o).noalias() += s.S.transpose() * uk;
      y.template segment<NU>(o + NX).noalias() = s.S * xk;
      y.template segment<NU>(o + NX).noalias() += s.R * uk;
    }
    y.template tail<NX>().noalias() = p->terminal.Q * x.template tail<NX>();
  }

  void cons_mul(const VecV& x, VecA& y) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const int o = k * NW, r = k * (NX + NG);
      const auto xk = x.template segment<NX>(o);
      const auto uk = x.template segment<NU>(o + NX);
      auto dyn = y.template segment<NX>(r);
      dyn = x.template segment<NX>(o + NW);
      dyn.noalias() -= s.A * xk;
      dyn.noalias() -= s.B * uk;
      auto gen = y.template segment<NG>(r + NX);
      gen.noalias() = s.C * xk;
      gen.noalias() += s.D * uk;
    }
    y.template tail<NGN>().noalias() = p->terminal.C * x.template tail<NX>();
  }

  void cons_tmul(const VecA& l, VecV& y) const {
    y.template tail<NX>().noalias() = p->terminal.C.transpose() * l.template tail<NGN>();
    for (int k = N - 1; k >= 0; --k) {
      const auto& s = p->stage[k];
      const int o = k * NW, r = k * (NX + NG);
      const auto ld = l.template segment<NX>(r);
      const auto lg = l.template segment<NG>(r + NX);
      y.template segment<NX>(o + NW) += ld;  // x_{k+1} (set by the previous pass)
      auto yx = y.template segment<NX>(o);
      auto yu = y.template segment<NU>(o + NX);
      yx.noalias() = s.C.transpose() * lg;
      yx.noalias() -= s.A.transpose() * ld;
      yu.noalias() = s.D.transpose() * lg;
      yu.noalias() -= s.B.transpose() * ld;
    }
  }

  static int stage_of(int i) {
    const int k = i < NV ? i / NW : (i - NV) / (NX + NG);
    return k < N ? k : N;
  }
  void mark_changed(int i) {
    const int k = stage_of(i);
    if (k < dirty_from)
      dirty_from = k;
  }
  void mark_all() { dirty_from = 0; }

  void row_norms_sq(VecA& n) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const int r = k * (NX + NG);
      n.template segment<NX>(r) = s.A.rowwise().squaredNorm() + s.B.rowwise().squaredNorm();
      n.template segment<NX>(r).array() += Scalar(1);
      n.template segment<NG>(r + NX) = s.C.rowwise().squaredNorm() + s.D.rowwise().squaredNorm();
    }
    n.template tail<NGN>() = p->terminal.C.rowwise().squaredNorm();
  }

  int factorize(const std::int8_t* ws, Scalar delta, Scalar w, const VecA& wa) {
    int done = 0;
    Eigen::Matrix<Scalar, NX, NX> wa_a;  // E_k A_k (dynamics rows weighted)
    Eigen::Matrix<Scalar, NX, NU> wa_b;  // E_k B_k
    for (int k = dirty_from; k < N; ++k, ++done) {
      const auto& s = p->stage[k];
      // copied: Eigen's diagonal product assumes an aligned diagonal, a segment at k (NX+NG)
      // is not (found by valgrind with NX + NG = 17)
      const VecX wd = wa.template segment<NX>(k * (NX + NG));
      wa_a.noalias() = wd.asDiagonal() * s.A;
      wa_b.noalias() = wd.asDiagonal() * s.B;
      MatW& d = u_diag[k];
      d.template topLeftCorner<NX, NX>() = s.Q;
      d.template bottomLeftCorner<NU, NX>() = s.S;
      d.template topRightCorner<NX, NU>() = s.S.transpose();
      d.template bottomRightCorner<NU, NU>() = s.R;
      d.template topLeftCorner<NX, NX>().noalias() += s.A.transpose() * wa_a;
      d.template topRightCorner<NX, NU>().noalias() += s.A.transpose() * wa_b;
      d.template bottomRightCorner<NU, NU>().noalias() += s.B.transpose() * wa_b;
      d.diagonal().array() += delta;
      const std::int8_t* wsb = ws + k * NW;
      for (int i = 0; i < NW; ++i) {
        if (wsb[i] != kInactive)
          d(i, i) += w;
      }
      const int rg = NV + k * (NX + NG) + NX;
      for (int j = 0; j < NG; ++j) {
        if (ws[rg + j] == kInactive)
          continue;
        const Scalar wj = wa(rg - NV + j);
        for (int c = 0; c < NW; ++c) {
          const Scalar ac = wj * (c < NX ? s.C(j, c) : s.D(j, c - NX));
          if (ac == Scalar(0))
            continue;
          for (int r = 0; r <= c; ++r)
            d(r, c) += ac * (r < NX ? s.C(j, r) : s.D(j, r - NX));
        }
      }
      if (k > 0) {
        const VecX wp = wa.template segment<NX>((k - 1) * (NX + NG));
        d.template topLeftCorner<NX, NX>().diagonal() += wp;
        d.template topLeftCorner<NX, NX>().noalias() -= u_off[k - 1].transpose() * u_off[k - 1];
      }
      if (!cholesky_upper_in_place(d))
        return -1;
      MatWX& o = u_off[k];
      o.template topRows<NX>() = -wa_a.transpose();
      o.template bottomRows<NU>() = -wa_b.transpose();
      solve_upper_transposed_columns(d, o);
    }
    if (dirty_from <= N) {
      const auto& t = p->terminal;
      MatX& d = u_term;
      d = t.Q;
      d.diagonal().array() += delta;
      const VecX wp = wa.template segment<NX>((N - 1) * (NX + NG));
      d.diagonal() += wp;
      const std::int8_t* wsb = ws + N * NW;
      for (int i = 0; i < NX; ++i) {
        if (wsb[i] != kInactive)
          d(i, i) += w;
      }
      const int rg = NV + N * (NX + NG);
      for (int j = 0; j < NGN; ++j) {
        if (ws[rg + j] == kInactive)
          continue;
        const Scalar wj = wa(rg - NV + j);
        for (int c = 0; c < NX; ++c) {
          const Scalar ac = wj * t.C(j, c);
          if (ac == Scalar(0))
            continue;
          for (int r = 0; r <= c; ++r)
            d(r, c) += ac * t.C(j, r);
        }
      }
      d.noalias() -= u_off[N - 1].transpose() * u_off[N - 1];
      if (!cholesky_upper_in_place(d))
        return -1;
      ++done;
    }
    dirty_from = N + 1;
    return done;
  }

  void solve(VecV& b) const {
    VecW v;
    VecX vx;
    for (int k = 0; k < N; ++k) {
      v = b.template segment<NW>(k * NW);
      if (k > 0) {
        v.template head<NX>().noalias() -=
            u_off[k - 1].transpose() * b.template segment<NW>((k - 1) * NW);
      }
      solve_upper_transposed(u_diag[k], v);
      b.template segment<NW>(k * NW) = v;
    }
    vx = b.template tail<NX>();
    vx.noalias() -= u_off[N - 1].transpose() * b.template segment<NW>((N - 1) * NW);
    solve_upper_transposed(u_term, vx);
    solve_upper(u_term, vx);
    b.template tail<NX>() = vx;
    for (int k = N - 1; k >= 0; --k) {
      v = b.template segment<NW>(k * NW);
      v.noalias() -= u_off[k] * b.template segment<NX>((k + 1) * NW);
      solve_upper(u_diag[k], v);
      b.template segment<NW>(k * NW) = v;
    }
  }
};

}  // namespace detail

/// Structure-exploiting active-set solver for an OcpQp type `Qp` (see the top of this file).
template <typename Qp>
class OcpQpSolver;

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
class OcpQpSolver<OcpQp<Scalar, N, NX, NU, NG, NGN>> {
 public:
  using Problem = OcpQp<Scalar, N, NX, NU, NG, NGN>;
  static constexpr int nv = Problem::nv;  ///< variables
  static constexpr int na = Problem::na;  ///< constraint rows (dynamics included)
  using Core = detail::ActiveSetCore<Scalar, nv, na>;
  using Backend = detail::OcpBackend<Scalar, N, NX, NU, NG, NGN>;

  /// Checks the data (finite, bounds ordered, every stage Hessian positive semidefinite) and
  /// keeps a reference to it. Returns solved on success, else the problem's status. The current
  /// iterate is kept (warm start); call cold_start() to reset it.
  QpStatus setup(const Problem& p, const QpSettings<Scalar>& s = QpSettings<Scalar>{}) {
    ready_ = false;
    settings_ = s;
    constexpr int NW = NX + NU;
    for (int k = 0; k < N; ++k) {
      const auto& st = p.stage[k];
      if (!st.Q.allFinite() || !st.S.allFinite() || !st.R.allFinite() || !st.q.allFinite() ||
          !st.r.allFinite() || !st.A.allFinite() || !st.B.allFinite() || !st.b.allFinite() ||
          !st.C.allFinite() || !st.D.allFinite()) {
        return QpStatus::non_finite;
      }
      for (QpStatus c : {detail::check_bounds(st.lbx, st.ubx), detail::check_bounds(st.lbu, st.ubu),
                         detail::check_bounds(st.lg, st.ug)}) {
        if (c != QpStatus::solved)
          return c;
      }
    }
    const auto& t = p.terminal;
    if (!t.Q.allFinite() || !t.q.allFinite() || !t.C.allFinite())
      return QpStatus::non_finite;
    for (QpStatus c : {detail::check_bounds(t.lbx, t.ubx), detail::check_bounds(t.lg, t.ug)}) {
      if (c != QpStatus::solved)
        return c;
    }
    for (int k = 0; k < N; ++k) {
      const auto& st = p.stage[k];
      Eigen::Matrix<Scalar, NW, NW> h;
      h.template topLeftCorner<NX, NX>() = st.Q;
      h.template bottomLeftCorner<NU, NX>() = st.S;
      h.template topRightCorner<NX, NU>() = st.S.transpose();
      h.template bottomRightCorner<NU, NU>() = st.R;
      if (!detail::is_psd(h, s.psd_tolerance))
        return QpStatus::non_convex;
    }
    if (!detail::is_psd(t.Q, s.psd_tolerance))
      return QpStatus::non_convex;

    be_.p = &p;
    for (int k = 0; k < N; ++k) {
      const auto& st = p.stage[k];
      const int o = Problem::state_offset(k), r = Problem::dynamics_offset(k);
      core_.lbx.template segment<NX>(o) = st.lbx;
      core_.ubx.template segment<NX>(o) = st.ubx;
      core_.lbx.template segment<NU>(o + NX) = st.lbu;
      core_.ubx.template segment<NU>(o + NX) = st.ubu;
      core_.g.template segment<NX>(o) = st.q;
      core_.g.template segment<NU>(o + NX) = st.r;
      core_.lba.template segment<NX>(r) = st.b;
      core_.uba.template segment<NX>(r) = st.b;
      core_.lba.template segment<NG>(r + NX) = st.lg;
      core_.uba.template segment<NG>(r + NX) = st.ug;
    }
    core_.lbx.template tail<NX>() = t.lbx;
    core_.ubx.template tail<NX>() = t.ubx;
    core_.g.template tail<NX>() = t.q;
    core_.lba.template tail<NGN>() = t.lg;
    core_.uba.template tail<NGN>() = t.ug;
    if (!initialized_)
      cold_start();
    ready_ = true;
    return QpStatus::solved;
  }

  /// Resets the iterate: x = projection of 0 onto the bounds, multipliers 0.
  void cold_start() {
    core_.cold_start();
    initialized_ = true;
  }

  /// Solves from the current iterate (warm start: the last solution, or values written through
  /// x(), lam_x(), lam_a()).
  QpStatus solve() {
    if (!ready_)
      return QpStatus::not_setup;
    return core_.solve(be_, settings_, info_);
  }

  /// Flat primal iterate (layout in problem.hpp).
  Eigen::Matrix<Scalar, nv, 1>& x() { return core_.x; }
  /// Multipliers of the variable bounds (> 0: upper active, < 0: lower active).
  Eigen::Matrix<Scalar, nv, 1>& lam_x() { return core_.lam_x; }
  /// Multipliers of the rows: dynamics and stage constraints (layout in problem.hpp).
  Eigen::Matrix<Scalar, na, 1>& lam_a() { return core_.lam_a; }
  /// State x_k, k = 0..N.
  Eigen::Matrix<Scalar, NX, 1> state(int k) const {
    return core_.x.template segment<NX>(Problem::state_offset(k));
  }
  /// Input u_k, k = 0..N-1.
  Eigen::Matrix<Scalar, NU, 1> input(int k) const {
    return core_.x.template segment<NU>(Problem::input_offset(k));
  }
  /// Report of the last solve.
  const SolveInfo<Scalar>& info() const { return info_; }
  /// Settings in use (may be changed between solves).
  QpSettings<Scalar>& settings() { return settings_; }

 private:
  Core core_;                      ///< iterate, bounds and active-set workspace
  Backend be_;                     ///< block-tridiagonal factorization
  QpSettings<Scalar> settings_{};  ///< settings of the next solve
  SolveInfo<Scalar> info_{};       ///< report of the last solve
  bool ready_ = false;             ///< setup() succeeded
  bool initialized_ = false;       ///< the iterate holds values
};

}  // namespace arbor::qp
