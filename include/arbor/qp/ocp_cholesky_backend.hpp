// arbor::qp::detail: the first linear algebra of the OCP solver, a block-tridiagonal Cholesky
// (upper factor, dot-product kernels, refactorization from the first changed stage). Kept as the
// reference the default backend (ocp_backend.hpp) is compared with in tests and benchmarks:
// OcpQpSolver<Qp, OcpCholeskyBackend<...>> selects it.
//
// Each iteration of the active-set method (active_set.hpp) solves with
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
// Cost: O(N (NX+NU)^3) per factorization, O(N (NX+NU)^2) per solve and per product with H or A.
// Memory (scalars): N (NW^2 + NW NX) + NX^2 for the factor; the problem's matrices are read
// through a pointer (the copy/reference rule is in ocp_qp_solver.hpp).
#pragma once

#include <Eigen/Core>
#include <array>

#include "arbor/qp/backend.hpp"
#include "arbor/qp/cholesky.hpp"
#include "arbor/qp/problem.hpp"

namespace arbor::qp::detail {

/// Block-tridiagonal Cholesky backend for ActiveSetCore on an OcpQp (the reference backend).
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
struct OcpCholeskyBackend {
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

  int factorize(const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
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
      const ConstraintState* wsb = ws + k * NW;
      for (int i = 0; i < NW; ++i) {
        if (wsb[i] != ConstraintState::inactive)
          d(i, i) += w;
      }
      const int rg = NV + k * (NX + NG) + NX;
      for (int j = 0; j < NG; ++j) {
        if (ws[rg + j] == ConstraintState::inactive)
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
      const ConstraintState* wsb = ws + N * NW;
      for (int i = 0; i < NX; ++i) {
        if (wsb[i] != ConstraintState::inactive)
          d(i, i) += w;
      }
      const int rg = NV + N * (NX + NG);
      for (int j = 0; j < NGN; ++j) {
        if (ws[rg + j] == ConstraintState::inactive)
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

}  // namespace arbor::qp::detail
