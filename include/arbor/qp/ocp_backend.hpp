// arbor::qp::detail: the linear algebra of the OCP solver: a block elimination of the stage-wise
// KKT matrix with vectorisable fixed-size kernels, and rank-one factor updates for working-set
// changes.
//
// Each iteration of the active-set method (active_set.hpp) solves with
//   M = H + delta I + A_W' E A_W     (E: regularisation weights, see active_set.hpp)
// where A_W holds the dynamics rows (always active) and the active bounds and stage constraints.
// H is block diagonal, an active bound or stage row touches one stage and the dynamics row dyn_k
// touches w_k = (x_k, u_k) and x_{k+1}, so M is block tridiagonal with diagonal blocks of size
// NW = NX + NU (NX for the terminal stage). It is factorized as M = L L' with L block lower
// bidiagonal, eliminating the stages in order:
//   L_kk L_kk' = M_kk - [X_{k-1} X_{k-1}' on the x_k x_k corner]   (Cholesky, NW x NW)
//   X_k = L_{k+1,k} = -E_k [A_k B_k] L_kk^-T                        (NX x NW)
// with M_kk = G_k + [A_k B_k]' E_k [A_k B_k] + E_{k-1} (x corner), G_k the stage Hessian plus
// delta, the weights of the active bounds and C_j' e_j C_j of the active rows. This is the
// Riccati recursion of the penalised problem run forward (the Schur complement of x_{k+1} is the
// cost-to-go of the backward recursion); both orders cost the same. Per stage, in multiply-adds:
// NW (NW+1)/2 NX (E-weighted dynamics), NX (NX+1)/2 NW (corner), NW^3/6 (Cholesky),
// NX NW^2/2 (X_k): 14.8 k for NX = 16, NU = 8.
// Kernels: the lower factor is stored column-major and every inner loop is an axpy over a
// contiguous column (vectorised by the compiler without reassociation; the reference backend in
// ocp_cholesky_backend.hpp uses dot products, which are not).
//
// Working-set changes: a bound or a row that enters or leaves the working set changes M by
// +-e v v' with v supported on one stage k (v = e_i for a bound, the row [C_j D_j] for a path
// row). The factor is updated by a rank-one update (or downdate) that sweeps stages k..N:
// O(NW (NW + NX)) per stage instead of O(NW^3), whatever k is. A downdate whose pivot would lose
// more than half the working precision (r^2 < sqrt(eps) L_jj^2) is abandoned and the stages from
// k on are refactorized instead; after max_updates updates the next factorization is a full one
// (round-off of the updates does not accumulate). Side switches (lower <-> upper) do not change M.
// Memory (scalars): N (NW^2 + NW NX) + NX^2 for the factor (as the reference backend), plus
// NV + NA bytes (the working set the factor holds).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "arbor/qp/backend.hpp"
#include "arbor/qp/problem.hpp"

namespace arbor::qp::detail {

/// Lower Cholesky L L' = a in place (lower triangle read and written, upper never read), left-
/// looking with contiguous column updates; false on a pivot that is not positive and finite.
template <typename Mat>
bool cholesky_lower_in_place(Mat& a) {
  using Scalar = typename Mat::Scalar;
  constexpr int n = Mat::RowsAtCompileTime;
  static_assert(n == Mat::ColsAtCompileTime, "square matrix expected");
  Scalar* d = a.data();
  for (int j = 0; j < n; ++j) {
    Scalar* cj = d + j * n;
    for (int k = 0; k < j; ++k) {
      const Scalar* ck = d + k * n;
      const Scalar s = ck[j];
      for (int r = j; r < n; ++r)
        cj[r] -= s * ck[r];
    }
    const Scalar p = cj[j];
    if (!(p > Scalar(0)) || !std::isfinite(p))
      return false;
    const Scalar l = std::sqrt(p);
    cj[j] = l;
    const Scalar inv = Scalar(1) / l;
    for (int r = j + 1; r < n; ++r)
      cj[r] *= inv;
  }
  return true;
}

/// Solves L y = b in place (L lower from cholesky_lower_in_place), column-oriented.
template <typename MatL, typename Vec>
void solve_lower(const MatL& l, Vec& b) {
  constexpr int n = MatL::RowsAtCompileTime;
  for (int j = 0; j < n; ++j) {
    const auto yj = b(j) / l(j, j);
    b(j) = yj;
    for (int r = j + 1; r < n; ++r)
      b(r) -= yj * l(r, j);
  }
}

/// Solves L' y = b in place (back substitution with dot products over columns of L).
template <typename MatL, typename Vec>
void solve_lower_transposed(const MatL& l, Vec& b) {
  using Scalar = typename MatL::Scalar;
  constexpr int n = MatL::RowsAtCompileTime;
  for (int j = n - 1; j >= 0; --j) {
    Scalar s = b(j);
    for (int r = j + 1; r < n; ++r)
      s -= l(r, j) * b(r);
    b(j) = s / l(j, j);
  }
}

/// Block-elimination backend with rank-one updates for ActiveSetCore on an OcpQp (the default).
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
struct OcpBackend {
  using Problem = OcpQp<Scalar, N, NX, NU, NG, NGN>;
  static constexpr int NW = NX + NU;
  static constexpr int NV = Problem::nv;
  static constexpr int NA = Problem::na;
  static constexpr int NZ = NV + NA;
  /// Pending working-set changes kept for rank-one updates; more refactorize instead.
  static constexpr int max_pending = 8;
  /// Updates applied since the last full factorization before the next one is full.
  static constexpr int max_updates = 2 * N + 8;
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;
  using VecW = Eigen::Matrix<Scalar, NW, 1>;
  using VecX = Eigen::Matrix<Scalar, NX, 1>;
  using MatW = Eigen::Matrix<Scalar, NW, NW>;
  using MatXW = Eigen::Matrix<Scalar, NX, NW>;
  using MatX = Eigen::Matrix<Scalar, NX, NX>;

  const Problem* p = nullptr;               ///< referenced problem
  std::array<MatW, N> l_diag;               ///< L_kk (lower triangle)
  std::array<MatXW, N> l_off;               ///< X_k = L_{k+1,k}, rows of x_{k+1}
  MatX l_term;                              ///< L_NN (lower triangle)
  int dirty_from = 0;                       ///< first stage to refactorize (N+1: none)
  int updates = 0;                          ///< rank-one updates since the last full factorization
  int updates_last = 0;                     ///< rank-one updates made by the last factorize()
  std::array<int, max_pending> pending{};   ///< changed constraints not yet in the factor
  int n_pending = 0;                        ///< how many
  std::array<std::int8_t, NZ> in_factor{};  ///< 1: constraint i is active in the factor
  Scalar w_ = 0;                            ///< bound weight of the factor
  Scalar delta_ = 0;                        ///< delta of the factor

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
    if (n_pending < max_pending) {
      pending[n_pending++] = i;
      return;
    }
    const int k = stage_of(i);
    if (k < dirty_from)
      dirty_from = k;
  }
  void mark_all() {
    dirty_from = 0;
    n_pending = 0;
  }

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
    updates_last = 0;
    if (dirty_from > 0 && (delta != delta_ || w != w_ || updates >= max_updates))
      dirty_from = 0;
    if (dirty_from == 0) {
      n_pending = 0;
      updates = 0;
    }
    delta_ = delta;
    w_ = w;
    // working-set changes in stages before dirty_from: rank-one updates where they are safe
    for (int c = 0; c < n_pending; ++c) {
      const int i = pending[c];
      const int k = stage_of(i);
      const std::int8_t now = ws[i] != ConstraintState::inactive ? 1 : 0;
      if (k >= dirty_from || now == in_factor[i])
        continue;
      if (rank_one(i, k, now != 0, w, wa)) {
        in_factor[i] = now;
        ++updates;
        ++updates_last;
      } else {
        dirty_from = k;
      }
    }
    n_pending = 0;
    int done = 0;
    for (int k = dirty_from; k < N; ++k, ++done) {
      if (!factor_stage(k, ws, delta, w, wa))
        return -1;
    }
    if (dirty_from <= N) {
      if (!factor_terminal(ws, delta, w, wa))
        return -1;
      ++done;
      for (int i = dirty_from * NW; i < NV; ++i)
        in_factor[i] = ws[i] != ConstraintState::inactive ? 1 : 0;
      for (int i = NV + dirty_from * (NX + NG); i < NZ; ++i)
        in_factor[i] = ws[i] != ConstraintState::inactive ? 1 : 0;
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
        const MatXW& x = l_off[k - 1];
        for (int j = 0; j < NW; ++j) {
          const Scalar y = b(NW * (k - 1) + j);
          for (int r = 0; r < NX; ++r)
            v(r) -= y * x(r, j);
        }
      }
      solve_lower(l_diag[k], v);
      b.template segment<NW>(k * NW) = v;
    }
    vx = b.template tail<NX>();
    {
      const MatXW& x = l_off[N - 1];
      for (int j = 0; j < NW; ++j) {
        const Scalar y = b(NW * (N - 1) + j);
        for (int r = 0; r < NX; ++r)
          vx(r) -= y * x(r, j);
      }
    }
    solve_lower(l_term, vx);
    solve_lower_transposed(l_term, vx);
    b.template tail<NX>() = vx;
    for (int k = N - 1; k >= 0; --k) {
      v = b.template segment<NW>(k * NW);
      const auto z = b.template segment<NX>((k + 1) * NW);
      const MatXW& x = l_off[k];
      for (int j = 0; j < NW; ++j) {
        Scalar s = v(j);
        for (int r = 0; r < NX; ++r)
          s -= x(r, j) * z(r);
        v(j) = s;
      }
      solve_lower_transposed(l_diag[k], v);
      b.template segment<NW>(k * NW) = v;
    }
  }

 private:
  /// D(c:n, c) += a_c * a(c:n) * wgt for every column c (lower part of wgt a a').
  template <typename Mat, typename Vec>
  static void add_rank_one_lower(Mat& d, const Vec& a, Scalar wgt) {
    constexpr int n = Mat::RowsAtCompileTime;
    for (int c = 0; c < n; ++c) {
      const Scalar s = wgt * a(c);
      if (s == Scalar(0))
        continue;
      for (int r = c; r < n; ++r)
        d(r, c) += s * a(r);
    }
  }

  bool factor_stage(int k, const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
    const auto& s = p->stage[k];
    const int r0 = k * (NX + NG);
    MatW& d = l_diag[k];
    d.template topLeftCorner<NX, NX>() = s.Q;
    d.template bottomLeftCorner<NU, NX>() = s.S;
    d.template bottomRightCorner<NU, NU>() = s.R;
    const ConstraintState* wsb = ws + k * NW;
    for (int i = 0; i < NW; ++i)
      d(i, i) += delta + (wsb[i] != ConstraintState::inactive ? w : Scalar(0));
    for (int j = 0; j < NG; ++j) {
      if (ws[NV + r0 + NX + j] == ConstraintState::inactive)
        continue;
      VecW a;
      for (int c = 0; c < NW; ++c)
        a(c) = c < NX ? s.C(j, c) : s.D(j, c - NX);
      add_rank_one_lower(d, a, wa(r0 + NX + j));
    }
    // E-weighted dynamics: d += [A B]' E [A B] (lower), t(:, i) = row i of [A B]
    Eigen::Matrix<Scalar, NW, NX> t;
    t.template topRows<NX>() = s.A.transpose();
    t.template bottomRows<NU>() = s.B.transpose();
    Scalar wd[NX];
    for (int i = 0; i < NX; ++i)
      wd[i] = wa(r0 + i);
    for (int c = 0; c < NW; ++c) {
      Scalar* dc = d.data() + c * NW;
      for (int i = 0; i < NX; ++i) {
        const Scalar* ti = t.data() + i * NW;
        const Scalar f = wd[i] * ti[c];
        for (int r = c; r < NW; ++r)
          dc[r] += f * ti[r];
      }
    }
    if (k > 0) {
      const Scalar* wp = wa.data() + (k - 1) * (NX + NG);
      const MatXW& xp = l_off[k - 1];
      for (int c = 0; c < NX; ++c) {
        d(c, c) += wp[c];
        d.col(c).segment(c, NX - c).noalias() -= xp.middleRows(c, NX - c) * xp.row(c).transpose();
      }
    }
    if (!cholesky_lower_in_place(d))
      return false;
    // X_k = -E [A B] L^-T: column j = (-E [A B](:, j) - sum_{i<j} X(:, i) L(j, i)) / L(j, j)
    MatXW& x = l_off[k];
    const VecX wdv = wa.template segment<NX>(r0);  // copied: the segment is not aligned
    x.template leftCols<NX>().noalias() = -(wdv.asDiagonal() * s.A);
    x.template rightCols<NU>().noalias() = -(wdv.asDiagonal() * s.B);
    for (int j = 0; j < NW; ++j) {
      auto xj = x.col(j);
      for (int i = 0; i < j; ++i)
        xj -= d(j, i) * x.col(i);
      xj *= Scalar(1) / d(j, j);
    }
    return true;
  }

  bool factor_terminal(const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
    const auto& t = p->terminal;
    MatX& d = l_term;
    d = t.Q;
    const ConstraintState* wsb = ws + N * NW;
    const Scalar* wp = wa.data() + (N - 1) * (NX + NG);
    for (int i = 0; i < NX; ++i)
      d(i, i) += delta + wp[i] + (wsb[i] != ConstraintState::inactive ? w : Scalar(0));
    const int rg = N * (NX + NG);
    for (int j = 0; j < NGN; ++j) {
      if (ws[NV + rg + j] == ConstraintState::inactive)
        continue;
      VecX a;
      for (int c = 0; c < NX; ++c)
        a(c) = t.C(j, c);
      add_rank_one_lower(d, a, wa(rg + j));
    }
    const MatXW& xp = l_off[N - 1];
    for (int c = 0; c < NX; ++c)
      d.col(c).segment(c, NX - c).noalias() -= xp.middleRows(c, NX - c) * xp.row(c).transpose();
    return cholesky_lower_in_place(d);
  }

  /// One column step of a rank-one update (sigma = +1) or downdate (-1) of L L' by v v':
  /// column j of the diagonal block ld (n rows) and of the block below it, lo (NX rows, may be
  /// null), with the parts v (n) and vo (NX) of the vector. False when a downdate is unsafe:
  /// r^2 <= tol L_jj^2 (tol = sqrt(eps): more than half the digits of the pivot would be lost).
  template <int n>
  static bool rotate_column(Scalar* ld, Scalar* lo, Scalar* v, Scalar* vo, int j, Scalar sigma,
                            Scalar tol) {
    const Scalar vj = v[j];
    if (vj == Scalar(0))
      return true;
    const Scalar ljj = ld[j];
    const Scalar l2 = ljj * ljj;
    const Scalar r2 = l2 + sigma * vj * vj;
    if (!(r2 > tol * l2) || !std::isfinite(r2))
      return false;
    const Scalar r = std::sqrt(r2);
    const Scalar c = r / ljj, sn = vj / ljj, ic = ljj / r;
    ld[j] = r;
    v[j] = 0;
    for (int i = j + 1; i < n; ++i) {
      const Scalar li = (ld[i] + sigma * sn * v[i]) * ic;
      ld[i] = li;
      v[i] = c * v[i] - sn * li;
    }
    if (lo != nullptr) {
      for (int i = 0; i < NX; ++i) {
        const Scalar li = (lo[i] + sigma * sn * vo[i]) * ic;
        lo[i] = li;
        vo[i] = c * vo[i] - sn * li;
      }
    }
    return true;
  }

  /// Adds (active) or removes the term of constraint i (stage k) by a rank-one sweep over stages
  /// k..dirty_from-1 (and the terminal block when it is valid); false when a downdate is unsafe
  /// (the caller refactorizes from stage k).
  bool rank_one(int i, int k, bool active, Scalar w, const VecA& wa) {
    const Scalar sigma = active ? Scalar(1) : Scalar(-1);
    const Scalar tol = std::sqrt(std::numeric_limits<Scalar>::epsilon());
    VecW v = VecW::Zero();
    VecX vx;
    if (i < NV) {
      const int loc = i - k * NW;
      if (k < N) {
        v(loc) = std::sqrt(w);
      } else {
        vx.setZero();
        vx(loc) = std::sqrt(w);
      }
    } else {
      const int j = i - NV - k * (NX + NG) - (k < N ? NX : 0);
      const Scalar sw = std::sqrt(wa(i - NV));
      if (k < N) {
        const auto& s = p->stage[k];
        for (int c = 0; c < NW; ++c)
          v(c) = sw * (c < NX ? s.C(j, c) : s.D(j, c - NX));
      } else {
        for (int c = 0; c < NX; ++c)
          vx(c) = sw * p->terminal.C(j, c);
      }
    }
    const int last = dirty_from < N ? dirty_from : N;  // stages k..last-1 are swept
    for (int s = k; s < last; ++s) {
      vx.setZero();
      Scalar* ld = l_diag[s].data();
      Scalar* lo = l_off[s].data();
      for (int j = 0; j < NW; ++j) {
        if (!rotate_column<NW>(ld + j * NW, lo + j * NX, v.data(), vx.data(), j, sigma, tol))
          return false;
      }
      v.template head<NX>() = vx;
      v.template tail<NU>().setZero();
    }
    if (dirty_from <= N)
      return true;  // the terminal block is refactorized anyway
    if (k < N)
      vx = v.template head<NX>();
    Scalar* ld = l_term.data();
    for (int j = 0; j < NX; ++j) {
      if (!rotate_column<NX>(ld + j * NX, nullptr, vx.data(), nullptr, j, sigma, tol))
        return false;
    }
    return true;
  }
};

}  // namespace arbor::qp::detail
