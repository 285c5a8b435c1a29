// arbor::qp::detail: exact-dynamics linear algebra of the OCP solver: a backward square-root
// Riccati recursion on the stage blocks, with the dynamics rows solved exactly (no proximal
// weight) and their multipliers (the costates) returned by the solve; an ExactRowBackend
// (backend.hpp).
//
// Each iteration of the active-set method (active_set.hpp) solves, for the working set W,
//   G dx + D' dnu = f,   D dx = e
// with D the dynamics rows dyn_k = x_{k+1} - A_k x_k - B_k u_k (exact), G block diagonal: the
// stage Hessian [Q S'; S R] plus delta I, the weight w of the active bounds and e_j c_j c_j' of the
// active path rows (the proximal terms of active_set.hpp, unchanged). Per stage, with the stage
// variables ordered (u_k, x_k) and F_k = [B_k A_k]:
//   P_N = G_N = L_N L_N'
//   M_k = G_k + F_k' P_{k+1} F_k = L_k L_k'    (Cholesky, NW = NU + NX; (u, x) order)
//   P_k = Lxx_k Lxx_k'                         (the Schur complement of u_k in M_k: the trailing
//                                               NX x NX block of L_k, no extra work)
// F_k' P_{k+1} F_k is formed as T' T with T = Lxx_{k+1}' F_k (triangular times dense). Per stage
// in multiply-adds: NX^2 NW / 2 (T) + NW (NW+1) NX / 2 (T' T) + NW^3 / 6 (Cholesky):
// 3.1 k + 4.8 k + 2.3 k = 10.2 k for NX = 16, NU = 8 (the penalised block elimination it
// replaced: 14.8 k), no product with X_k, no 1/eps weights in the matrix.
// solve_exact(): backward, h_k = f_k + F_k' Lxx_{k+1} (y_{x,k+1} - Lxx_{k+1}' e_k), y_k =
// L_k^-1 h_k; forward, from dx_0 = L_0^-T y_0: du_k = Luu^-T (y_u - Lxu' dx_k), the costate
// dnu_{k-1} = Lxx_k (y_{x,k} - Lxx_k' dx_k), dx_{k+1} = F_k dw_k + e_k. ~NW^2 / 2 + NU NW + 4 NX NW
// + 2 NX^2 multiply-adds per stage (1.8 k for the Kinova size; the penalised solve: 1.3 k).
// Two variants skip what a known-zero right-hand side makes zero: ZeroRhs (e and the fixed steps
// zero: refine_step()) and InitialOnly (only x_0's fixed steps nonzero: the presolved feedback's
// response, active_set.hpp; the backward sweep of stages N..1 is skipped).
// Measured (bench/qp/RESULTS.md, SSE2): factorization 559 k instructions for N = 16 (the
// penalised one: 753 k), one solve_exact ~113 k with the four [A B] products per stage (Eigen's
// gemv, ~46 % of it; the packed triangular products and solves the rest; the penalised solve
// ~45 k); with AVX2+FMA and the [A B] products written per column (ocp_products.hpp,
// lazy_products) the factorization takes 199 k (OCP-FD) and one solve_exact ~73 k. This is the
// default backend of OcpQpSolver (ocp_qp_solver.hpp).
// Exact bounds (exact_bound()): a working bound of an input u_k or of x_0 fixes its variable
// instead of adding the weight w: its row and column of M_k become the unit vector (the
// recursion runs on the other variables; P_k is the Schur complement of the free inputs only).
// solve_exact() moves G_k c and F_k c (c: the fixed variables' steps) to the right-hand sides,
// and returns their multipliers dlam_j = f_j - (G_k dw)_j + (F_k' dnu_k)_j. (A bound on x_k,
// k >= 1, would be an equality on stage k-1's variables through the dynamics: those bounds keep
// the weight.) Fixing a variable deletes its column of L_k (the part below the diagonal is
// rotated into the later columns: an update, always safe), freeing one inserts the column again
// (row j left of the diagonal by a triangular solve, then a downdate of the later columns); both
// carry P_k's change down like a rank-one update.
// Working-set changes: a bound or path row of stage k changes M_k by +-v v'; the rank-one update
// (downdate) of L_k leaves, after its u columns, the vector v^ with P_k +-= v^ v^', so M_{k-1}
// changes by +-(F_{k-1}' v^)(F_{k-1}' v^)': one sweep from stage k down to stage 0,
// O(NW^2 + NX NW) per stage. An unsafe downdate (r^2 < sqrt(eps) L_jj^2) refactorizes stages
// k..0 instead (k + 1 stage factorizations); after max_updates updates the next factorization
// is a full one.
// Memory (scalars): N NW (NW+1)/2 + NX (NX+1)/2 for the factor (no off-diagonal blocks: ~49 KB
// less than the penalised elimination's at the Kinova size in double), plus NV + NA bytes. Stack: an NW x NW
// scratch, [B A]', T' and an unpacked Lxx during a stage's factorization (the transposed copies
// by kernels::transpose, T' assigned by the product, M_k's upper part not filled where the kernels
// do not read it).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "arbor/qp/backend.hpp"
#include "arbor/qp/kernels.hpp"
#include "arbor/qp/ocp_products.hpp"
#include "arbor/qp/packed_kernels.hpp"
#include "arbor/qp/problem.hpp"

namespace arbor::qp::detail {

/// Exact-dynamics Riccati backend for ActiveSetCore on an OcpQp (see the top of this file).
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
struct OcpRiccatiBackend : OcpProducts<Scalar, N, NX, NU, NG, NGN> {
  using Products = OcpProducts<Scalar, N, NX, NU, NG, NGN>;
  using Products::p;
  using Products::stage_of;
  using Problem = OcpQp<Scalar, N, NX, NU, NG, NGN>;
  static constexpr int NW = NX + NU;
  static constexpr int NR = NX + NG;  ///< rows per path stage
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
  using MatX = Eigen::Matrix<Scalar, NX, NX>;
  static constexpr int PW = kernels::packed_size(NW);  ///< scalars of a packed L_k
  static constexpr int PX = kernels::packed_size(NX);  ///< scalars of the packed L_N

  std::array<std::array<Scalar, PW>, N> l_stage;  ///< L_k, packed lower, (u, x) order
  std::array<Scalar, PX> l_term;                  ///< L_N, packed lower
  int dirty_to = N;      ///< stages dirty_to..0 must be refactorized (-1: none; N: terminal too)
  int updates = 0;       ///< rank-one updates since the last full factorization
  int updates_last = 0;  ///< rank-one updates made by the last factorize()
  std::array<int, max_pending> pending{};   ///< changed constraints not yet in the factor
  int n_pending = 0;                        ///< how many
  std::array<std::int8_t, NZ> in_factor{};  ///< 1: constraint i is active in the factor
  Scalar w_ = 0;                            ///< bound weight of the factor
  Scalar delta_ = 0;                        ///< delta of the factor
  /// Per-variable weights added to the diagonal of every stage block (NV entries, flat layout;
  /// nullptr: none), on top of delta and w: the barrier curvature of the interior-point cold
  /// start (ocp_interior_point.hpp). While set, every factorize() is a full one.
  const Scalar* diag_weights = nullptr;

  /// The rows solved exactly: the dynamics rows dyn_k, k < N.
  static constexpr bool exact_row(int j) { return j < N * NR && j % NR < NX; }
  /// The bounds held exactly while in the working set (the variable is fixed, removed from the
  /// recursion): those of the inputs u_k, k < N, and of the initial state x_0. (A bound on x_k,
  /// k >= 1, would be an equality on stage k-1's variables through the dynamics: those keep the
  /// proximal weight, as do the path rows.)
  static constexpr bool exact_bound(int i) { return i < N * NW && (i < NX || i % NW >= NX); }

  void mark_changed(int i) {
    if (n_pending < max_pending) {
      pending[n_pending++] = i;
      return;
    }
    const int k = stage_of(i);
    if (k > dirty_to)
      dirty_to = k;
  }
  void mark_all() {
    dirty_to = N;
    n_pending = 0;
  }

  int factorize(const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
    updates_last = 0;
    if (dirty_to < N &&
        (delta != delta_ || w != w_ || updates >= max_updates || diag_weights != nullptr))
      dirty_to = N;
    if (dirty_to == N) {
      n_pending = 0;
      updates = 0;
    }
    delta_ = delta;
    w_ = w;
    // changes in stages after dirty_to: rank-one sweeps where they are safe
    for (int c = 0; c < n_pending; ++c) {
      const int i = pending[c];
      const int k = stage_of(i);
      const std::int8_t now = ws[i] != ConstraintState::inactive ? 1 : 0;
      if (k <= dirty_to || now == in_factor[i])
        continue;
      if (exact_bound(i)) {
        // fixing a variable deletes its column (then an update), freeing one inserts it (then a
        // downdate); an unsafe one refactorizes stages k..0
        if (now != 0 ? fix_variable(i, k) : free_variable(i, k, wa)) {
          in_factor[i] = now;
          ++updates;
          ++updates_last;
        } else {
          dirty_to = k;
        }
        continue;
      }
      if (rank_one(i, k, now != 0, w, wa)) {
        in_factor[i] = now;
        ++updates;
        ++updates_last;
      } else {
        dirty_to = k;
      }
    }
    n_pending = 0;
    int done = 0;
    if (dirty_to == N) {
      if (!factor_terminal(ws, delta, w, wa))
        return -1;
      ++done;
    }
    for (int k = (dirty_to < N ? dirty_to : N - 1); k >= 0; --k, ++done) {
      if (!factor_stage(k, ws, delta, w, wa))
        return -1;
    }
    if (dirty_to >= 0) {
      const int kend = dirty_to + 1;  // constraints of stages 0..dirty_to are in the factor
      const int nb = kend * NW < NV ? kend * NW : NV;
      for (int i = 0; i < nb; ++i)
        in_factor[i] = ws[i] != ConstraintState::inactive ? 1 : 0;
      const int nr = kend * NR < NA ? kend * NR : NA;
      for (int i = NV; i < NV + nr; ++i)
        in_factor[i] = ws[i] != ConstraintState::inactive ? 1 : 0;
    }
    dirty_to = -1;
    return done;
  }

  /// v <- dx, a_D <- dnu, c_B <- dlam_B (backend.hpp, ExactRowBackend); a_D holds e and c_B the
  /// steps of the fixed variables on entry; wa: the row weights of factorize().
  /// ZeroRhs: the caller vouches that e and the fixed steps are zero (active_set.hpp's
  /// refine_step()): the products with e are skipped (the same values, to the sign of a zero).
  /// InitialOnly: the caller vouches that v and e are zero and that the only nonzero fixed steps
  /// are x_0's (the response of the step to a move of the initial state, active_set.hpp's
  /// solve_from()): the backward sweep of stages N..1 is skipped (its y_k are zero), stage 0's
  /// and the forward sweep run as usual: ~45 % of a solve fewer multiply-adds.
  template <bool ZeroRhs = false, bool InitialOnly = false>
  void solve_exact(VecV& v, VecA& a, VecV& c, const VecA& wa) const {
    static_assert(!(ZeroRhs && InitialOnly), "one kind of right-hand side");
    Scalar* f = v.data();
    // backward: y_k = L_k^-1 h_k, kept in v's stage segment in (u, x) order
    Scalar* yn = f + N * NW;
    if constexpr (!InitialOnly)
      solve_lower_packed<NX>(l_term.data(), yn);
    const Scalar* ynext = yn;  // y_{x,k+1}
    const Scalar* lnext = l_term.data();
    int nnext = NX;  // order of the packed factor holding Lxx_{k+1} (its trailing NX block)
    for (int k = N - 1; k >= 0; --k) {
      const auto& s = p->stage[k];
      Scalar* fk = f + k * NW;
      if constexpr (InitialOnly) {
        if (k > 0) {  // zero right-hand side, no fixed step: y_k = 0 (v is zero there)
          ynext = fk + NU;
          lnext = l_stage[k].data();
          nnext = NW;
          continue;
        }
      }
      // fixed variables (step cw): f -= G_k cw on the free ones (f_j kept in c for the
      // multiplier), e_k += F_k cw; their own entries of h are set to cw below
      VecW cw;
      VecX ekf;
      const Scalar* ek = a.data() + k * NR;
      const int any = fixed_rhs(k, fk, c, wa, cw);
      if (any == 2) {
        if (k == 0)
          ekf.noalias() = Eigen::Map<const VecX>(ek) + prod(s.B, cw.template head<NU>()) +
                          prod(s.A, cw.template tail<NX>());
        else
          ekf.noalias() = Eigen::Map<const VecX>(ek) + prod(s.B, cw.template head<NU>());
        ek = ekf.data();
      }
      // r = y_{x,k+1} - Lxx_{k+1}' e_k, then s = Lxx_{k+1} r
      VecX r, sx;
      const Scalar* rp = ynext;  // r = y_{x,k+1} when e_k = 0
      if constexpr (!ZeroRhs) {
        if (nnext == NX) {
          lt_mul_tail<NX>(lnext, ek, r.data());
        } else {
          lt_mul_tail<NW>(lnext, ek, r.data());
        }
        for (int i = 0; i < NX; ++i)
          r(i) = ynext[i] - r(i);
        rp = r.data();
      }
      if (nnext == NX) {
        l_mul_tail<NX>(lnext, rp, sx.data());
      } else {
        l_mul_tail<NW>(lnext, rp, sx.data());
      }
      // h = [f_u; f_x] + [B A]' s
      VecW h;
      if constexpr (lazy_products) {
        if constexpr (NU > 0) {
          for (int i = 0; i < NU; ++i)
            h(i) = fk[NX + i] + s.B.col(i).dot(sx);
        }
        for (int i = 0; i < NX; ++i)
          h(NU + i) = fk[i] + s.A.col(i).dot(sx);
      } else {
        h.template head<NU>() = Eigen::Map<const Eigen::Matrix<Scalar, NU, 1>>(fk + NX);
        h.template head<NU>().noalias() += s.B.transpose() * sx;
        h.template tail<NX>() = Eigen::Map<const VecX>(fk);
        h.template tail<NX>().noalias() += s.A.transpose() * sx;
      }
      if (any > 0) {
        for (int j = 0; j < (k == 0 ? NW : NU); ++j) {
          if (is_fixed(k, j))
            h(j) = cw(j);
        }
      }
      solve_lower_packed<NW>(l_stage[k].data(), h.data());
      Eigen::Map<VecW>{fk} = h;
      ynext = fk + NU;
      lnext = l_stage[k].data();
      nnext = NW;
    }
    // forward: stage 0 solves its whole block (x_0 has no costate before it)
    VecW dw;  // (u, x) order
    dw = Eigen::Map<const VecW>(f);
    solve_lower_transposed_packed<NW>(l_stage[0].data(), dw.data());
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      Scalar* fk = f + k * NW;
      if (k > 0) {
        // dw holds [y_u; dx_k]: the costate of x_k, then du_k
        Scalar* nu = a.data() + (k - 1) * NR;
        costate<NW>(l_stage[k].data(), fk + NU, dw.data() + NU, nu);
        for (int i = 0; i < NU; ++i)
          dw(i) = fk[i];
        solve_lower_transposed_head<NW, NU>(l_stage[k].data(), dw.data());
      }
      // dx_{k+1} = A dx_k + B du_k + e_k
      VecX xn;
      if constexpr (ZeroRhs || InitialOnly)
        xn.setZero();
      else
        xn = Eigen::Map<const VecX>(a.data() + k * NR);
      if constexpr (lazy_products) {
        for (int j = 0; j < NX; ++j)
          xn += s.A.col(j) * dw(NU + j);
        if constexpr (NU > 0) {
          for (int j = 0; j < NU; ++j)
            xn += s.B.col(j) * dw(j);
        }
      } else {
        xn.noalias() += s.A * dw.template tail<NX>();
        xn.noalias() += s.B * dw.template head<NU>();
      }
      Eigen::Map<VecX>{fk} = dw.template tail<NX>();
      Eigen::Map<Eigen::Matrix<Scalar, NU, 1>>(fk + NX) = dw.template head<NU>();
      dw.template tail<NX>() = xn;
    }
    Scalar* fn = f + N * NW;
    costate<NX>(l_term.data(), fn, dw.data() + NU, a.data() + (N - 1) * NR);
    Eigen::Map<VecX>{fn} = dw.template tail<NX>();
    // multipliers of the fixed variables: dlam_j = f_j - (G_k dw_k)_j - (D' dnu)_j
    for (int k = 0; k < N; ++k)
      fixed_multipliers(k, f + k * NW, a.data() + k * NR, c, wa);
  }

 private:
  /// Flat index of the bound of stage k's variable at position j of the (u, x) order.
  static constexpr int flat_bound(int k, int j) { return k * NW + (j < NU ? NX + j : j - NU); }
  /// Position in the (u, x) order of stage k's block of the flat bound i.
  static constexpr int block_pos(int i) {
    const int loc = i % NW;
    return loc < NX ? NU + loc : loc - NX;
  }
  /// Whether the variable at (u, x) position j of stage k is fixed in the factor.
  bool is_fixed(int k, int j) const {
    return (j < NU || k == 0) && in_factor[flat_bound(k, j)] != 0;
  }
  /// Zeroes the entries of the fixed variables of stage k (they are not in the recursion).
  void zero_fixed(int k, VecW& v) const {
    for (int j = 0; j < NU; ++j) {
      if (in_factor[k * NW + NX + j] != 0)
        v(j) = 0;
    }
    if (k == 0) {
      for (int i = 0; i < NX; ++i) {
        if (in_factor[i] != 0)
          v(NU + i) = 0;
      }
    }
  }

  /// m * v as an unrolled fixed-size product where Eigen vectorises it (lazy_products), else
  /// Eigen's gemv.
  template <typename M, typename V>
  static auto prod(const M& m, const V& v) {
    if constexpr (lazy_products)
      return m.lazyProduct(v);
    else
      return (m * v).eval();
  }

  /// The weighted residuals w_r (C x + D u)_r of stage k's active path rows (0 elsewhere).
  template <typename VU, typename VX>
  Eigen::Matrix<Scalar, NG, 1> path_weighted(int k, const VU& u, const VX& x, bool with_x,
                                             const VecA& wa) const {
    const auto& s = p->stage[k];
    Eigen::Matrix<Scalar, NG, 1> t;
    if (with_x)
      t.noalias() = prod(s.D, u) + prod(s.C, x);
    else
      t.noalias() = prod(s.D, u);
    for (int r = 0; r < NG; ++r) {
      const int row = k * NR + NX + r;
      t(r) = in_factor[NV + row] != 0 ? wa(row) * t(r) : Scalar(0);
    }
    return t;
  }

  /// Stage k's fixed variables: cw <- their steps (from c; zeros elsewhere), c_j <- f_j (kept for
  /// their multipliers), f (flat (x, u) of stage k) -= G_k cw. Returns 0 when the stage has no
  /// fixed variable, 1 when their steps are all zero (nothing else to do), 2 otherwise.
  int fixed_rhs(int k, Scalar* fk, VecV& c, const VecA& wa, VecW& cw) const {
    int any = 0;
    const int jend = k == 0 ? NW : NU;  // x_0 is fixed in stage 0 only
    for (int j = 0; j < jend; ++j) {
      if (!is_fixed(k, j)) {
        cw(j) = 0;
        continue;
      }
      const int i = flat_bound(k, j);
      cw(j) = c(i);
      c(i) = fk[i - k * NW];
      any = std::max(any, cw(j) != Scalar(0) ? 2 : 1);
    }
    // (set although only the fixed entries are read when any < 2: GCC -O3 cannot see that,
    // -Wmaybe-uninitialized on the bare-metal targets)
    for (int j = jend; j < NW; ++j)
      cw(j) = 0;
    if (any < 2)
      return any;
    const auto& s = p->stage[k];
    // G_k cw, (u, x) order: [R S; S' Q] cw + the active path rows' w_r a_r a_r' cw (delta I
    // touches the fixed entries only); x_0's part only in stage 0
    const auto cu = cw.template head<NU>();
    const auto cx = cw.template tail<NX>();
    Eigen::Matrix<Scalar, NU, 1> gu;
    VecX gx;
    gu.noalias() = prod(s.R, cu);
    gx.noalias() = prod(s.S.transpose(), cu);
    if (k == 0) {
      gu.noalias() += prod(s.S, cx);
      gx.noalias() += prod(s.Q, cx);
    }
    if constexpr (NG > 0) {
      const Eigen::Matrix<Scalar, NG, 1> t = path_weighted(k, cu, cx, k == 0, wa);
      gu.noalias() += prod(s.D.transpose(), t);
      gx.noalias() += prod(s.C.transpose(), t);
    }
    Eigen::Map<VecX>{fk} -= gx;
    Eigen::Map<Eigen::Matrix<Scalar, NU, 1>>{fk + NX} -= gu;
    return 2;
  }

  /// c_j <- dlam_j = f_j - (G_k dw_k)_j + (F_k' dnu_k)_j for stage k's fixed variables (c_j holds
  /// f_j from fixed_rhs(); dw: the flat (x, u) step of stage k, nu: the costate of dyn_k).
  void fixed_multipliers(int k, const Scalar* dwk, const Scalar* nu, VecV& c,
                         const VecA& wa) const {
    const int jend = k == 0 ? NW : NU;
    bool any = false;
    for (int j = 0; j < jend && !any; ++j)
      any = is_fixed(k, j);
    if (!any)
      return;
    const auto& s = p->stage[k];
    const Eigen::Map<const VecX> dx(dwk), dn(nu);
    const Eigen::Map<const Eigen::Matrix<Scalar, NU, 1>> du(dwk + NX);
    // the weighted residuals of the active path rows, then row j of G_k dw - F_k' dnu for each
    // fixed j only (a stage has few)
    Scalar t[NG > 0 ? NG : 1];
    for (int r = 0; r < NG; ++r) {
      const int row = k * NR + NX + r;
      t[r] = 0;
      if (in_factor[NV + row] == 0)
        continue;
      Scalar v = 0;
      for (int c = 0; c < NU; ++c)
        v += s.D(r, c) * du(c);
      for (int c = 0; c < NX; ++c)
        v += s.C(r, c) * dx(c);
      t[r] = wa(row) * v;
    }
    for (int j = 0; j < jend; ++j) {
      if (!is_fixed(k, j))
        continue;
      Scalar gj = 0;
      if (j < NU) {
        if constexpr (NU > 0) {
          gj = s.R.col(j).dot(du) + s.S.row(j).dot(dx) - s.B.col(j).dot(dn) + delta_ * du(j);
          for (int r = 0; r < NG; ++r)
            gj += s.D(r, j) * t[r];
        }
      } else {
        const int q = j - NU;
        gj = s.S.col(q).dot(du) + s.Q.col(q).dot(dx) - s.A.col(q).dot(dn) + delta_ * dx(q);
        for (int r = 0; r < NG; ++r)
          gj += s.C(r, q) * t[r];
      }
      c(flat_bound(k, j)) -= gj;
    }
  }

  /// Column j of the packed lower triangle of order n, indexed by row: col(l, j)[r] = L(r, j).
  template <int n>
  static const Scalar* col(const Scalar* l, int j) {
    return l + kernels::packed_col(n, j) - j;
  }
  template <int n>
  static Scalar* col(Scalar* l, int j) {
    return l + kernels::packed_col(n, j) - j;
  }

  /// out = Lxx' v, Lxx the trailing NX x NX block of the packed lower l (order n): four dot
  /// products at a time (columns i..i+3), sharing the loads of v.
  template <int n>
  static void lt_mul_tail(const Scalar* l, const Scalar* v, Scalar* out) {
    constexpr int o = n - NX;
    int i = 0;
    for (; i + 4 <= NX; i += 4) {
      const Scalar* c0 = col<n>(l, o + i) + o;
      const Scalar* c1 = col<n>(l, o + i + 1) + o;
      const Scalar* c2 = col<n>(l, o + i + 2) + o;
      const Scalar* c3 = col<n>(l, o + i + 3) + o;
      const Scalar v0 = v[i], v1 = v[i + 1], v2 = v[i + 2], v3 = v[i + 3];
      Scalar s0 = c0[i] * v0 + c0[i + 1] * v1 + c0[i + 2] * v2 + c0[i + 3] * v3;
      Scalar s1 = c1[i + 1] * v1 + c1[i + 2] * v2 + c1[i + 3] * v3;
      Scalar s2 = c2[i + 2] * v2 + c2[i + 3] * v3;
      Scalar s3 = c3[i + 3] * v3;
      for (int r = i + 4; r < NX; ++r) {
        const Scalar y = v[r];
        s0 += c0[r] * y;
        s1 += c1[r] * y;
        s2 += c2[r] * y;
        s3 += c3[r] * y;
      }
      out[i] = s0;
      out[i + 1] = s1;
      out[i + 2] = s2;
      out[i + 3] = s3;
    }
    for (; i < NX; ++i) {
      const Scalar* c = col<n>(l, o + i) + o;
      Scalar t = 0;
      for (int r = i; r < NX; ++r)
        t += c[r] * v[r];
      out[i] = t;
    }
  }

  /// out = Lxx v, Lxx the trailing NX x NX block of the packed lower l (order n): four
  /// columns at a time, the sums in out (restrict: no aliasing with l or v, vectorised over
  /// rows). (Not in a local array: GCC 12 at -O3 -march=native with AVX-512 over-aligned such a
  /// leaf function's array for its vector stores and placed it 16 bytes off the 32-byte boundary
  /// those stores need: a segfault at nx = 14, tests/qp's Issue35CrashSize in the AVX-512
  /// builds, unseen before this suite ran on an AVX-512 machine.)
  template <int n>
  static void l_mul_tail(const Scalar* l, const Scalar* v, Scalar* __restrict out) {
    constexpr int o = n - NX;
    Scalar* acc = out;
    for (int r = 0; r < NX; ++r)
      acc[r] = 0;
    int i = 0;
    for (; i + 4 <= NX; i += 4) {
      const Scalar* c0 = col<n>(l, o + i) + o;
      const Scalar* c1 = col<n>(l, o + i + 1) + o;
      const Scalar* c2 = col<n>(l, o + i + 2) + o;
      const Scalar* c3 = col<n>(l, o + i + 3) + o;
      const Scalar v0 = v[i], v1 = v[i + 1], v2 = v[i + 2], v3 = v[i + 3];
      acc[i] += c0[i] * v0;
      acc[i + 1] += c0[i + 1] * v0 + c1[i + 1] * v1;
      acc[i + 2] += c0[i + 2] * v0 + c1[i + 2] * v1 + c2[i + 2] * v2;
      acc[i + 3] += c0[i + 3] * v0 + c1[i + 3] * v1 + c2[i + 3] * v2 + c3[i + 3] * v3;
      for (int r = i + 4; r < NX; ++r)
        acc[r] += c0[r] * v0 + c1[r] * v1 + c2[r] * v2 + c3[r] * v3;
    }
    for (; i < NX; ++i) {
      const Scalar* c = col<n>(l, o + i) + o;
      const Scalar vi = v[i];
      for (int r = i; r < NX; ++r)
        acc[r] += c[r] * vi;
    }
  }

  /// nu = Lxx (y_x - Lxx' dx), Lxx the trailing block of the packed lower l (order n).
  template <int n>
  static void costate(const Scalar* l, const Scalar* yx, const Scalar* dx, Scalar* nu) {
    Scalar t[NX];
    lt_mul_tail<n>(l, dx, t);
    for (int i = 0; i < NX; ++i)
      t[i] = yx[i] - t[i];
    l_mul_tail<n>(l, t, nu);
  }

  /// D(c:n, c) += wgt a_c a(c:n) for every column c.
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

  /// Row j of [D_j C_j] of path stage k in (u, x) order.
  VecW path_row(int k, int j) const {
    const auto& s = p->stage[k];
    VecW a;
    for (int c = 0; c < NU; ++c)
      a(c) = s.D(j, c);
    for (int c = 0; c < NX; ++c)
      a(NU + c) = s.C(j, c);
    return a;
  }

  /// Unpacks the trailing NX x NX block of the packed lower l (order n) into u (zeros above).
  template <int n>
  static void unpack_tail(const Scalar* l, MatX& u) {
    constexpr int o = n - NX;
    // copies of compile-time length per column (unrolled, vectorised)
    [&]<int... I>(std::integer_sequence<int, I...>) {
      ((u.col(I).template head<I>().setZero(),
        u.col(I).template tail<NX - I>() =
            Eigen::Map<const Eigen::Matrix<Scalar, NX - I, 1>>(col<n>(l, o + I) + o + I)),
       ...);
    }
    (std::make_integer_sequence<int, NX>{});
  }

  bool factor_stage(int k, const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
    using namespace kernels;
    const auto& s = p->stage[k];
    MatW d;  // M_k in (u, x) order, then L_k (full square scratch)
    d.template topLeftCorner<NU, NU>() = s.R;
    // S' below R; the upper part (S) is read only as scratch, by a diagonal block of the kernels
    // that straddles u and x
    transpose<NU, NX, NU, NW>(s.S.data(), d.data() + NU);
    if constexpr (NU % nb != 0)
      d.template topRightCorner<NU, NX>() = s.S;
    d.template bottomRightCorner<NX, NX>() = s.Q;
    const ConstraintState* wsb = ws + k * NW;
    for (int i = 0; i < NX; ++i)
      d(NU + i, NU + i) += delta + (wsb[i] != ConstraintState::inactive ? w : Scalar(0));
    for (int i = 0; i < NU; ++i)
      d(i, i) += delta + (wsb[NX + i] != ConstraintState::inactive ? w : Scalar(0));
    if (diag_weights != nullptr) {
      const Scalar* dw = diag_weights + k * NW;
      for (int i = 0; i < NX; ++i)
        d(NU + i, NU + i) += dw[i];
      for (int i = 0; i < NU; ++i)
        d(i, i) += dw[NX + i];
    }
    if constexpr (NG > 0) {
      // + sum over the active path rows of w_j a_j a_j': one product of the register-blocked
      // kernel (a_j and w_j a_j as columns) instead of a rank-one loop per row
      const int r0 = k * NR;
      // zeroed: GCC -O3 (arm-none-eabi, -Werror) cannot see that only the first m columns
      // are read (-Wmaybe-uninitialized)
      Eigen::Matrix<Scalar, NW, NG> pa = Eigen::Matrix<Scalar, NW, NG>::Zero();
      Eigen::Matrix<Scalar, NW, NG> pw = Eigen::Matrix<Scalar, NW, NG>::Zero();
      int m = 0;
      for (int j = 0; j < NG; ++j) {
        if (ws[NV + r0 + NX + j] == ConstraintState::inactive)
          continue;
        pa.col(m) = path_row(k, j);
        pw.col(m) = wa(r0 + NX + j) * pa.col(m);
        ++m;
      }
      if (m > 0)
        gemm_nt_lower<NW, NW, NW, NW, 1, NW, Update::add>(d.data(), pa.data(), pw.data(), m);
    }
    // + F' P_{k+1} F = T' T, T = Lxx_{k+1}' F, F = [B A]; tt = T' (NW x NX), built as
    // tt = F' Lxx_{k+1}: tt(c, i) = sum_{r >= i} F(r, c) Lxx(r, i), by blocks of 4 columns i
    MatX lxx;
    if (k == N - 1)
      unpack_tail<NX>(l_term.data(), lxx);
    else
      unpack_tail<NW>(l_stage[k + 1].data(), lxx);
    Eigen::Matrix<Scalar, NW, NX> ft, tt;
    transpose<NX, NU, NX, NW>(s.B.data(), ft.data());
    transpose<NX, NX, NX, NW>(s.A.data(), ft.data() + NU);
    constexpr int full = NX - NX % nb;
    for (int i0 = 0; i0 < full; i0 += nb) {
      gemm_nt_cols<NW, nb, NW, 1, NX, NW, Update::assign>(
          tt.data() + i0 * NW, ft.data() + i0 * NW, lxx.data() + i0 * (NX + 1), 0, 0, NX - i0);
    }
    if constexpr (NX % nb > 0) {
      gemm_nt_cols<NW, NX % nb, NW, 1, NX, NW, Update::assign>(
          tt.data() + full * NW, ft.data() + full * NW, lxx.data() + full * (NX + 1), 0, 0,
          NX - full);
    }
    gemm_nt_lower<NW, NW, NW, NW, 1, NW, Update::add>(d.data(), tt.data(), tt.data(), NX);
    // fixed variables (working exact bounds) leave the recursion: unit row and column
    for (int j = 0; j < (k == 0 ? NW : NU); ++j) {  // (x_0 only in stage 0)
      if (ws[flat_bound(k, j)] != ConstraintState::inactive) {
        d.row(j).setZero();
        d.col(j).setZero();
        d(j, j) = 1;
      }
    }
    if (!potrf_lower<NW>(d.data()))
      return false;
    pack_lower<NW>(d.data(), l_stage[k].data());
    return true;
  }

  bool factor_terminal(const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
    using namespace kernels;
    const auto& t = p->terminal;
    MatX d = t.Q;
    const ConstraintState* wsb = ws + N * NW;
    for (int i = 0; i < NX; ++i)
      d(i, i) += delta + (wsb[i] != ConstraintState::inactive ? w : Scalar(0)) +
                 (diag_weights != nullptr ? diag_weights[N * NW + i] : Scalar(0));
    const int rg = N * NR;
    for (int j = 0; j < NGN; ++j) {
      if (ws[NV + rg + j] == ConstraintState::inactive)
        continue;
      VecX a;
      for (int c = 0; c < NX; ++c)
        a(c) = t.C(j, c);
      add_rank_one_lower(d, a, wa(rg + j));
    }
    if (!potrf_lower<NX>(d.data()))
      return false;
    pack_lower<NX>(d.data(), l_term.data());
    return true;
  }

  /// Rotates v into the columns j0.. of L_s (update sigma = +1, downdate -1); vx <- the x part
  /// of v after the u columns (the vector of P_s's change). False when a downdate is unsafe.
  bool rotate_stage(int s, VecW& v, int j0, VecX& vx, Scalar sigma, Scalar tol) {
    Scalar* l = l_stage[s].data();
    for (int j = j0; j < NU; ++j) {
      if (!rotate_packed_column<NW, 0>(l, nullptr, v.data(), nullptr, j, sigma, tol))
        return false;
    }
    vx = v.template tail<NX>();
    for (int j = j0 > NU ? j0 : NU; j < NW; ++j) {
      if (!rotate_packed_column<NW, 0>(l, nullptr, v.data(), nullptr, j, sigma, tol))
        return false;
    }
    return true;
  }

  /// Carries P_{s+1} +-= vx vx' down through stages s..dirty_to+1: M_s changes by F_s' vx
  /// (without the fixed variables' entries).
  bool sweep_down(int s, VecX vx, Scalar sigma, Scalar tol) {
    VecW v;
    for (; s > dirty_to && s >= 0; --s) {
      const auto& st = p->stage[s];
      if constexpr (lazy_products) {
        v.template head<NU>().noalias() = st.B.transpose().lazyProduct(vx);
        v.template tail<NX>().noalias() = st.A.transpose().lazyProduct(vx);
      } else {
        v.template head<NU>().noalias() = st.B.transpose() * vx;
        v.template tail<NX>().noalias() = st.A.transpose() * vx;
      }
      zero_fixed(s, v);
      if (!rotate_stage(s, v, 0, vx, sigma, tol))
        return false;
    }
    return true;
  }

  /// Fixes the variable of the exact bound i (stage k < N): its column of L_k is deleted (row
  /// and column set to the unit vector), the column's part below the diagonal, l, is rotated into
  /// the later columns (M_k without the variable is L' L'' + l l' there), and P_k's change
  /// carried down as for a rank-one update. False on a non-finite value.
  bool fix_variable(int i, int k) {
    const Scalar tol = std::sqrt(std::numeric_limits<Scalar>::epsilon());
    const int pj = block_pos(i);
    Scalar* l = l_stage[k].data();
    VecW v = VecW::Zero();
    Scalar* cj = col<NW>(l, pj);
    for (int r = pj + 1; r < NW; ++r) {
      v(r) = cj[r];
      cj[r] = 0;
    }
    cj[pj] = 1;
    for (int c = 0; c < pj; ++c)
      col<NW>(l, c)[pj] = 0;
    VecX vx = VecX::Zero();
    if (!rotate_stage(k, v, pj + 1, vx, Scalar(1), tol))
      return false;
    return k == 0 || sweep_down(k - 1, vx, Scalar(1), tol);
  }

  /// Frees the variable of the exact bound i (stage k < N): its column of M_k, m = G_k e_j +
  /// F_k' P_{k+1} F_k e_j (without the other fixed variables' entries), is inserted into L_k:
  /// row j left of the diagonal solves L_11 l = m_1, the diagonal is sqrt(m_jj - |l|^2), the
  /// column below it (m_2 - L_21 l) / L_jj = v, and the later columns lose v v' (a downdate,
  /// carried down as for a rank-one one). False when a pivot or a downdate is unsafe.
  bool free_variable(int i, int k, const VecA& wa) {
    const Scalar tol = std::sqrt(std::numeric_limits<Scalar>::epsilon());
    const int pj = block_pos(i);
    const auto& s = p->stage[k];
    in_factor[i] = 0;  // (refactorized from ws when this fails)
    VecX fc, t, sx;
    if constexpr (NU > 0) {
      if (pj < NU)
        fc = s.B.col(pj);
      else
        fc = s.A.col(pj - NU);
    } else {
      fc = s.A.col(pj - NU);
    }
    if (k == N - 1) {
      lt_mul_tail<NX>(l_term.data(), fc.data(), t.data());
      l_mul_tail<NX>(l_term.data(), t.data(), sx.data());
    } else {
      lt_mul_tail<NW>(l_stage[k + 1].data(), fc.data(), t.data());
      l_mul_tail<NW>(l_stage[k + 1].data(), t.data(), sx.data());
    }
    VecW m;
    m.template head<NU>().noalias() = prod(s.B.transpose(), sx);
    m.template tail<NX>().noalias() = prod(s.A.transpose(), sx);
    if (pj < NU) {
      if constexpr (NU > 0) {
        m.template head<NU>() += s.R.col(pj);
        m.template tail<NX>() += s.S.row(pj).transpose();
      }
    } else {
      m.template head<NU>() += s.S.col(pj - NU);
      m.template tail<NX>() += s.Q.col(pj - NU);
    }
    m(pj) += delta_;
    for (int r = 0; r < NG; ++r) {
      const int row = k * NR + NX + r;
      if (in_factor[NV + row] == 0)
        continue;
      const VecW ar = path_row(k, r);
      m += (wa(row) * ar(pj)) * ar;
    }
    zero_fixed(k, m);
    Scalar* l = l_stage[k].data();
    VecW lr = VecW::Zero();
    Scalar d2 = m(pj);
    for (int c = 0; c < pj; ++c) {
      Scalar v = m(c);
      for (int c2 = 0; c2 < c; ++c2)
        v -= col<NW>(l, c2)[c] * lr(c2);
      lr(c) = v / col<NW>(l, c)[c];
      d2 -= lr(c) * lr(c);
    }
    if (!(d2 > tol * m(pj)) || !std::isfinite(d2))
      return false;
    const Scalar ljj = std::sqrt(d2);
    VecW v = VecW::Zero();
    for (int r = pj + 1; r < NW; ++r) {
      Scalar val = m(r);
      for (int c = 0; c < pj; ++c)
        val -= col<NW>(l, c)[r] * lr(c);
      v(r) = val / ljj;
    }
    for (int c = 0; c < pj; ++c)
      col<NW>(l, c)[pj] = lr(c);
    Scalar* cj = col<NW>(l, pj);
    cj[pj] = ljj;
    for (int r = pj + 1; r < NW; ++r)
      cj[r] = v(r);
    VecX vx = VecX::Zero();
    if (!rotate_stage(k, v, pj + 1, vx, Scalar(-1), tol))
      return false;
    return k == 0 || sweep_down(k - 1, vx, Scalar(-1), tol);
  }

  /// Adds (active) or removes the term of constraint i (stage k) by a rank-one sweep over stages
  /// k..dirty_to+1; false when a downdate is unsafe (the caller refactorizes stages k..0).
  bool rank_one(int i, int k, bool active, Scalar w, const VecA& wa) {
    const Scalar sigma = active ? Scalar(1) : Scalar(-1);
    const Scalar tol = std::sqrt(std::numeric_limits<Scalar>::epsilon());
    VecX vx = VecX::Zero();
    if (k == N) {
      if (i < NV) {
        vx(i - N * NW) = std::sqrt(w);
      } else {
        const int j = i - NV - N * NR;
        const Scalar sw = std::sqrt(wa(i - NV));
        for (int c = 0; c < NX; ++c)
          vx(c) = sw * p->terminal.C(j, c);
      }
      VecX t = vx;
      for (int j = 0; j < NX; ++j) {
        if (!rotate_packed_column<NX, 0>(l_term.data(), nullptr, t.data(), nullptr, j, sigma, tol))
          return false;
      }
      return sweep_down(N - 1, vx, sigma, tol);
    }
    if (k <= dirty_to)
      return true;
    VecW v = VecW::Zero();
    if (i < NV) {
      v(block_pos(i)) = std::sqrt(w);
    } else {
      const int j = i - NV - k * NR - NX;
      v = std::sqrt(wa(i - NV)) * path_row(k, j);
    }
    zero_fixed(k, v);
    if (!rotate_stage(k, v, 0, vx, sigma, tol))
      return false;
    return sweep_down(k - 1, vx, sigma, tol);
  }
};

}  // namespace arbor::qp::detail
