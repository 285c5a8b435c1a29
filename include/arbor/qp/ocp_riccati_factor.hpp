// arbor::qp::detail: the state of the OCP solver's Riccati backend (the packed factors L_k of
// the stage blocks M_k, which constraints they hold, the pending working-set changes) and its
// factorization: factor_stage() forms M_k = G_k + F_k' P_{k+1} F_k and factors it, O(NW^3) per
// stage; factorize() refactorizes the stages a change made dirty and applies the others as
// rank-one updates (ocp_riccati_update.hpp). The recursion is described in
// ocp_riccati_backend.hpp.
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

/// Exact-dynamics Riccati backend for ActiveSetCore on an OcpQp (ocp_riccati_backend.hpp describes
/// the recursion; this file holds its state and the factorization, ocp_riccati_solve.hpp the solve,
/// ocp_riccati_update.hpp the rank-one updates after working-set changes).
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

  int factorize(const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa);

  /// v <- dx, a_D <- dnu, c_B <- dlam_B (backend.hpp, ExactRowBackend); a_D holds e and c_B the
  /// steps of the fixed variables on entry; wa: the row weights of factorize().
  /// ZeroRhs: the caller vouches that e and the fixed steps are zero (active_set.hpp's
  /// refine_step()): the products with e are skipped (the same values, to the sign of a zero).
  /// InitialOnly: the caller vouches that v and e are zero and that the only nonzero fixed steps
  /// are x_0's (the response of the step to a move of the initial state, active_set.hpp's
  /// solve_from()): the backward sweep of stages N..1 is skipped (its y_k are zero), stage 0's
  /// and the forward sweep run as usual: ~45 % of a solve fewer multiply-adds.
  template <bool ZeroRhs = false, bool InitialOnly = false>
  void solve_exact(VecV& v, VecA& a, VecV& c, const VecA& wa) const;

  /// Whether the factor holds exactly the working set ws (no pending change, nothing dirty):
  /// after a solve, false only when the solver returned an earlier iterate than its last step's
  /// (its best one, at a stall or the settings' cap). O(NV + NA) byte compares.
  bool holds(const ConstraintState* ws) const;

  /// The local feedback gain of stage k on the factor's working set: kg = -(M_uu)^-1 M_ux, with
  /// M_k = G_k + F_k' P_{k+1} F_k as factorized (the rows and columns of the fixed inputs removed:
  /// their rows of kg are zero). du_k = kg dx_k is the response of the equality-constrained QP
  /// of the working set to a move dx_k of x_k with x_k held (the states after it free). Stage
  /// k >= 1, or stage 0 with no x_0 fixed: from the factor, kg = -Luu^-T Lxu' (NU^2 NX / 2
  /// multiply-adds). Stage 0 with x_0 fixed (its columns of L_0 are deleted): M_ux = S_0 + (active
  /// path rows) + (Lxx_1' B_0)' (Lxx_1' A_0) recomputed from L_1, then two triangular solves with
  /// Luu_0: NW NX^2 / 2 + NU NX^2 + NU^2 NX multiply-adds (6.1 k for NX = 16, NU = 8).
  /// Call holds() first; the matrices must be the ones factorized.
  void feedback_gain(int k, Eigen::Matrix<Scalar, NU, NX>& kg) const;

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
                                             const VecA& wa) const;

  /// Stage k's fixed variables: cw <- their steps (from c; zeros elsewhere), c_j <- f_j (kept for
  /// their multipliers), f (flat (x, u) of stage k) -= G_k cw. Returns 0 when the stage has no
  /// fixed variable, 1 when their steps are all zero (nothing else to do), 2 otherwise.
  int fixed_rhs(int k, Scalar* fk, VecV& c, const VecA& wa, VecW& cw) const;

  /// c_j <- dlam_j = f_j - (G_k dw_k)_j + (F_k' dnu_k)_j for stage k's fixed variables (c_j holds
  /// f_j from fixed_rhs(); dw: the flat (x, u) step of stage k, nu: the costate of dyn_k).
  void fixed_multipliers(int k, const Scalar* dwk, const Scalar* nu, VecV& c, const VecA& wa) const;

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
  static void lt_mul_tail(const Scalar* l, const Scalar* v, Scalar* out);

  /// out = Lxx v, Lxx the trailing NX x NX block of the packed lower l (order n): four
  /// columns at a time, the sums in out (restrict: no aliasing with l or v, vectorised over
  /// rows). The sums stay in out, not in a local array: GCC 12 at -O3 -march=native with AVX-512
  /// misaligns such a leaf function's array for the 32-byte vector stores it emits (a segfault at
  /// nx = 14; tests/qp's Issue35CrashSize in the AVX-512 builds guards it).
  template <int n>
  static void l_mul_tail(const Scalar* l, const Scalar* v, Scalar* __restrict out);

  /// nu = Lxx (y_x - Lxx' dx), Lxx the trailing block of the packed lower l (order n).
  template <int n>
  static void costate(const Scalar* l, const Scalar* yx, const Scalar* dx, Scalar* nu);

  /// D(c:n, c) += wgt a_c a(c:n) for every column c.
  template <typename Mat, typename Vec>
  static void add_rank_one_lower(Mat& d, const Vec& a, Scalar wgt);

  /// Row j of [D_j C_j] of path stage k in (u, x) order.
  VecW path_row(int k, int j) const;

  /// Unpacks the trailing NX x NX block of the packed lower l (order n) into u (zeros above).
  template <int n>
  static void unpack_tail(const Scalar* l, MatX& u);

  bool factor_stage(int k, const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa);

  bool factor_terminal(const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa);

  /// Rotates v into the columns j0.. of L_s (update sigma = +1, downdate -1); vx <- the x part
  /// of v after the u columns (the vector of P_s's change). False when a downdate is unsafe.
  bool rotate_stage(int s, VecW& v, int j0, VecX& vx, Scalar sigma, Scalar tol);

  /// Carries P_{s+1} +-= vx vx' down through stages s..dirty_to+1: M_s changes by F_s' vx
  /// (without the fixed variables' entries).
  bool sweep_down(int s, VecX vx, Scalar sigma, Scalar tol);

  /// Fixes the variable of the exact bound i (stage k < N): its column of L_k is deleted (row
  /// and column set to the unit vector), the column's part below the diagonal, l, is rotated into
  /// the later columns (M_k without the variable is L' L'' + l l' there), and P_k's change
  /// carried down as for a rank-one update. False on a non-finite value.
  bool fix_variable(int i, int k);

  /// Frees the variable of the exact bound i (stage k < N): its column of M_k, m = G_k e_j +
  /// F_k' P_{k+1} F_k e_j (without the other fixed variables' entries), is inserted into L_k:
  /// row j left of the diagonal solves L_11 l = m_1, the diagonal is sqrt(m_jj - |l|^2), the
  /// column below it (m_2 - L_21 l) / L_jj = v, and the later columns lose v v' (a downdate,
  /// carried down as for a rank-one one). False when a pivot or a downdate is unsafe.
  bool free_variable(int i, int k, const VecA& wa);

  /// Adds (active) or removes the term of constraint i (stage k) by a rank-one sweep over stages
  /// k..dirty_to+1; false when a downdate is unsafe (the caller refactorizes stages k..0).
  bool rank_one(int i, int k, bool active, Scalar w, const VecA& wa);
};

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline int OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::factorize(const ConstraintState* ws,
                                                                    Scalar delta, Scalar w,
                                                                    const VecA& wa) {
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

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline bool OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::holds(const ConstraintState* ws) const {
  if (dirty_to != -1 || n_pending != 0)
    return false;
  bool same = true;
  for (int i = 0; i < NZ; ++i)
    same &= (ws[i] != ConstraintState::inactive) == (in_factor[i] != 0);
  return same;
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline void OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::feedback_gain(
    int k, Eigen::Matrix<Scalar, NU, NX>& kg) const {
  if constexpr (NU == 0) {
    (void)k;
    (void)kg;
  } else {
    const Scalar* l = l_stage[k].data();
    bool x_fixed = false;
    if (k == 0) {
      for (int i = 0; i < NX; ++i)
        x_fixed = x_fixed || in_factor[i] != 0;
    }
    if (!x_fixed) {
      // M_ux = Luu Lxu': kg(:, c) = -Luu^-T Lxu(c, :)' (a fixed input's column of L is the unit
      // vector: its row of Lxu is zero, and so is its row of kg)
      for (int c = 0; c < NX; ++c) {
        for (int j = NU - 1; j >= 0; --j) {
          const Scalar* lj = col<NW>(l, j);
          Scalar v = lj[NU + c];
          for (int r = j + 1; r < NU; ++r)
            v -= lj[r] * kg(r, c);
          kg(j, c) = v / lj[j];
        }
      }
      kg = -kg;
      return;
    }
    // x_0 fixed: M_ux from the stage's data and P_1 = Lxx_1 Lxx_1'; T = Lxx_1' [B A] column by
    // column
    const auto& s = p->stage[k];
    Eigen::Matrix<Scalar, NX, NU> tb;
    Eigen::Matrix<Scalar, NX, NX> ta;
    const auto lt_mul = [&](const Scalar* v, Scalar* out) {
      if constexpr (N == 1)
        lt_mul_tail<NX>(l_term.data(), v, out);
      else
        lt_mul_tail<NW>(l_stage[1].data(), v, out);
    };
    for (int c = 0; c < NU; ++c)
      lt_mul(s.B.col(c).data(), tb.col(c).data());
    for (int c = 0; c < NX; ++c)
      lt_mul(s.A.col(c).data(), ta.col(c).data());
    kg = s.S;
    kg.noalias() += tb.transpose().lazyProduct(ta);
    if constexpr (NG > 0) {
      // the active path rows' w_j d_j c_j', with the weights of the factorization: w / |a_j|^2
      // (active_set.hpp's row weights, from the same rows)
      for (int j = 0; j < NG; ++j) {
        if (in_factor[NV + k * NR + NX + j] == 0)
          continue;
        const Scalar n2 = s.C.row(j).squaredNorm() + s.D.row(j).squaredNorm();
        const Scalar wj = n2 > 0 ? w_ / n2 : w_;
        kg.noalias() += (wj * s.D.row(j).transpose()).lazyProduct(s.C.row(j));
      }
    }
    for (int j = 0; j < NU; ++j) {
      if (in_factor[NX + j] != 0)
        kg.row(j).setZero();
    }
    // kg = -Luu^-T Luu^-1 M_ux, column by column
    for (int c = 0; c < NX; ++c) {
      for (int j = 0; j < NU; ++j) {  // Luu z = m
        Scalar v = kg(j, c);
        for (int r = 0; r < j; ++r)
          v -= col<NW>(l, r)[j] * kg(r, c);
        kg(j, c) = v / col<NW>(l, j)[j];
      }
      for (int j = NU - 1; j >= 0; --j) {  // Luu' y = z
        const Scalar* lj = col<NW>(l, j);
        Scalar v = kg(j, c);
        for (int r = j + 1; r < NU; ++r)
          v -= lj[r] * kg(r, c);
        kg(j, c) = v / lj[j];
      }
    }
    kg = -kg;
  }
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
template <int n>
inline void OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::lt_mul_tail(const Scalar* l,
                                                                       const Scalar* v,
                                                                       Scalar* out) {
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

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
template <int n>
inline void OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::l_mul_tail(const Scalar* l,
                                                                      const Scalar* v,
                                                                      Scalar* __restrict out) {
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

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
template <int n>
inline void OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::costate(const Scalar* l,
                                                                   const Scalar* yx,
                                                                   const Scalar* dx, Scalar* nu) {
  Scalar t[NX];
  lt_mul_tail<n>(l, dx, t);
  for (int i = 0; i < NX; ++i)
    t[i] = yx[i] - t[i];
  l_mul_tail<n>(l, t, nu);
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
template <typename Mat, typename Vec>
inline void OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::add_rank_one_lower(Mat& d, const Vec& a,
                                                                              Scalar wgt) {
  constexpr int n = Mat::RowsAtCompileTime;
  for (int c = 0; c < n; ++c) {
    const Scalar s = wgt * a(c);
    if (s == Scalar(0))
      continue;
    for (int r = c; r < n; ++r)
      d(r, c) += s * a(r);
  }
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline auto OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::path_row(int k, int j) const -> VecW {
  const auto& s = p->stage[k];
  VecW a;
  for (int c = 0; c < NU; ++c)
    a(c) = s.D(j, c);
  for (int c = 0; c < NX; ++c)
    a(NU + c) = s.C(j, c);
  return a;
}

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
template <int n>
inline void OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::unpack_tail(const Scalar* l, MatX& u) {
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

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline bool OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::factor_stage(int k,
                                                                        const ConstraintState* ws,
                                                                        Scalar delta, Scalar w,
                                                                        const VecA& wa) {
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
    gemm_nt_cols<NW, nb, NW, 1, NX, NW, Update::assign>(tt.data() + i0 * NW, ft.data() + i0 * NW,
                                                        lxx.data() + i0 * (NX + 1), 0, 0, NX - i0);
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

template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
inline bool OcpRiccatiBackend<Scalar, N, NX, NU, NG, NGN>::factor_terminal(
    const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
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

}  // namespace arbor::qp::detail
