// arbor::qp::detail: the penalised linear algebra of the OCP solver (the default before the
// exact-dynamics Riccati backend, ocp_riccati_backend.hpp; opt-in through
// PenalisedOcpBackend in ocp_qp_solver.hpp): a block elimination of the stage-wise KKT matrix
// with vectorisable fixed-size kernels, and rank-one factor updates for working-set changes. The
// packed kernels and OcpProducts below are shared with the Riccati backend.
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
// Kernels (kernels.hpp): each stage block is assembled in a full NW x NW scratch matrix on the
// stack; the products ([A B]' E [A B], the x corner, the Cholesky's and X_k's updates) run in
// register-blocked 4 x 4 kernels with compile-time sizes, the 4-column panels in column axpys.
// The factor keeps L_kk and L_NN packed (lower triangles only). solve() works on the packed
// columns four at a time (forward: one pass over the rows below a 4 x 4 block; backward: four
// dot products sharing their loads) and multiplies by X_k with Eigen's fixed-size products.
//
// Working-set changes: a bound or a row that enters or leaves the working set changes M by
// +-e v v' with v supported on one stage k (v = e_i for a bound, the row [C_j D_j] for a path
// row). The factor is updated by a rank-one update (or downdate) that sweeps stages k..N:
// O(NW (NW + NX)) per stage instead of O(NW^3), whatever k is. A downdate whose pivot would lose
// more than half the working precision (r^2 < sqrt(eps) L_jj^2) is abandoned and the stages from
// k on are refactorized instead; after max_updates updates the next factorization is a full one
// (round-off of the updates does not accumulate). Side switches (lower <-> upper) do not change M.
// Memory (scalars): N (NW (NW+1)/2 + NW NX) + NX (NX+1)/2 for the factor, plus NV + NA bytes
// (the working set the factor holds); ~36 KB less than full L_kk blocks for the Kinova size in
// double. Stack: the NW x NW scratch and [A B]' (NW x NX) during a stage's factorization.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>

#include "arbor/qp/backend.hpp"
#include "arbor/qp/kernels.hpp"
#include "arbor/qp/problem.hpp"

namespace arbor::qp::detail {

/// The products with the problem's fixed-size blocks (H v, A v, A' v, the [A B] products of the
/// Riccati solve) as fixed-size products unrolled per column (M v: broadcast multiply-adds; M' v:
/// dot products of columns; a few as Eigen lazy products) where Eigen vectorises, and through its
/// runtime-size gemv otherwise: on the Cortex-M7 (no SIMD) the unrolled ones cost 2-5 % more
/// instructions (bench/qp/RESULTS.md).
#if defined(EIGEN_VECTORIZE)
inline constexpr bool lazy_products = true;
#else
inline constexpr bool lazy_products = false;
#endif

/// Solves L y = b in place, L lower of order n packed (kernels::packed_col): four columns at a
/// time, the 4 x 4 diagonal block first, then one pass over the rows below it; on a local copy
/// of b (no aliasing with l: the row passes vectorise without a runtime overlap test). The
/// pivots' inverses depend on l only, so the out-of-order core computes them ahead and the
/// chain through b carries multiplications, not divisions (~13 cycles of latency each on the
/// host; bench/qp/RESULTS.md: -5 % CPU time of a warm solve). Same for the back substitution.
template <int n, typename Scalar>
void solve_lower_packed(const Scalar* l, Scalar* bout) {
  Scalar b[n];
  for (int r = 0; r < n; ++r)
    b[r] = bout[r];
  int j = 0;
  for (; j + 4 <= n; j += 4) {
    // c_i[r] = L(r, j + i), r >= j + i
    const Scalar* c0 = l + kernels::packed_col(n, j) - j;
    const Scalar* c1 = l + kernels::packed_col(n, j + 1) - (j + 1);
    const Scalar* c2 = l + kernels::packed_col(n, j + 2) - (j + 2);
    const Scalar* c3 = l + kernels::packed_col(n, j + 3) - (j + 3);
    const Scalar i0 = Scalar(1) / c0[j], i1 = Scalar(1) / c1[j + 1];
    const Scalar i2 = Scalar(1) / c2[j + 2], i3 = Scalar(1) / c3[j + 3];
    const Scalar y0 = b[j] * i0;
    const Scalar y1 = (b[j + 1] - c0[j + 1] * y0) * i1;
    const Scalar y2 = (b[j + 2] - c0[j + 2] * y0 - c1[j + 2] * y1) * i2;
    const Scalar y3 = (b[j + 3] - c0[j + 3] * y0 - c1[j + 3] * y1 - c2[j + 3] * y2) * i3;
    b[j] = y0;
    b[j + 1] = y1;
    b[j + 2] = y2;
    b[j + 3] = y3;
    for (int r = j + 4; r < n; ++r)
      b[r] -= c0[r] * y0 + c1[r] * y1 + c2[r] * y2 + c3[r] * y3;
  }
  for (; j < n; ++j) {
    const Scalar* cj = l + kernels::packed_col(n, j) - j;
    const Scalar yj = b[j] * (Scalar(1) / cj[j]);
    b[j] = yj;
    for (int r = j + 1; r < n; ++r)
      b[r] -= yj * cj[r];
  }
  for (int r = 0; r < n; ++r)
    bout[r] = b[r];
}

/// Back substitution L' y = b for the first m unknowns of b (in place), L lower of order n
/// packed, the last n - m unknowns (already final) given: blocks of four columns whose dot
/// products with the solved part share its loads. m = n: the whole solve L' y = b.
template <int n, int m, typename Scalar>
void solve_lower_transposed_head(const Scalar* l, Scalar* b) {
  static_assert(0 <= m && m <= n);
  constexpr int tail = m % 4;
  for (int j = m - 1; j >= m - tail; --j) {
    const Scalar* cj = l + kernels::packed_col(n, j) - j;
    Scalar s = b[j];
    for (int r = j + 1; r < n; ++r)
      s -= cj[r] * b[r];
    b[j] = s * (Scalar(1) / cj[j]);
  }
  for (int j = m - tail - 4; j >= 0; j -= 4) {
    const Scalar* c0 = l + kernels::packed_col(n, j) - j;
    const Scalar* c1 = l + kernels::packed_col(n, j + 1) - (j + 1);
    const Scalar* c2 = l + kernels::packed_col(n, j + 2) - (j + 2);
    const Scalar* c3 = l + kernels::packed_col(n, j + 3) - (j + 3);
    Scalar s0 = b[j], s1 = b[j + 1], s2 = b[j + 2], s3 = b[j + 3];
    for (int r = j + 4; r < n; ++r) {
      const Scalar y = b[r];
      s0 -= c0[r] * y;
      s1 -= c1[r] * y;
      s2 -= c2[r] * y;
      s3 -= c3[r] * y;
    }
    const Scalar i0 = Scalar(1) / c0[j], i1 = Scalar(1) / c1[j + 1];
    const Scalar i2 = Scalar(1) / c2[j + 2], i3 = Scalar(1) / c3[j + 3];
    const Scalar y3 = s3 * i3;
    const Scalar y2 = (s2 - c2[j + 3] * y3) * i2;
    const Scalar y1 = (s1 - c1[j + 2] * y2 - c1[j + 3] * y3) * i1;
    const Scalar y0 = (s0 - c0[j + 1] * y1 - c0[j + 2] * y2 - c0[j + 3] * y3) * i0;
    b[j] = y0;
    b[j + 1] = y1;
    b[j + 2] = y2;
    b[j + 3] = y3;
  }
}

/// Solves L' y = b in place, L lower of order n packed.
template <int n, typename Scalar>
void solve_lower_transposed_packed(const Scalar* l, Scalar* b) {
  solve_lower_transposed_head<n, n>(l, b);
}

/// One column step of a rank-one update (sigma = +1) or downdate (-1) of L L' by v v': column j
/// of the packed lower block ld (order n) and of the m rows below it, lo (may be null when m is
/// 0), with the parts v (n) and vo (m) of the vector. False when a downdate is unsafe:
/// r^2 <= tol L_jj^2 (tol = sqrt(eps): more than half the digits of the pivot would be lost).
template <int n, int m, typename Scalar>
bool rotate_packed_column(Scalar* ld, std::type_identity_t<Scalar>* lo, Scalar* v,
                          std::type_identity_t<Scalar>* vo, int j, Scalar sigma, Scalar tol) {
  const Scalar vj = v[j];
  if (vj == Scalar(0))
    return true;
  Scalar* cj = ld + kernels::packed_col(n, j) - j;  // cj[i] = L(i, j), i >= j
  const Scalar ljj = cj[j];
  const Scalar l2 = ljj * ljj;
  const Scalar r2 = l2 + sigma * vj * vj;
  if (!(r2 > tol * l2) || !std::isfinite(r2))
    return false;
  const Scalar r = std::sqrt(r2);
  const Scalar c = r / ljj, sn = vj / ljj, ic = ljj / r;
  cj[j] = r;
  v[j] = 0;
  for (int i = j + 1; i < n; ++i) {
    const Scalar li = (cj[i] + sigma * sn * v[i]) * ic;
    cj[i] = li;
    v[i] = c * v[i] - sn * li;
  }
  for (int i = 0; i < m; ++i) {
    const Scalar li = (lo[i] + sigma * sn * vo[i]) * ic;
    lo[i] = li;
    vo[i] = c * vo[i] - sn * li;
  }
  return true;
}

/// Packs the lower triangle of a (order n, column-major, leading dimension n) into l.
template <int n, typename Scalar>
void pack_lower(const Scalar* a, Scalar* l) {
  // one copy of compile-time length per column (unrolled, vectorised; a runtime-bounded loop
  // per column cost ~4 instructions per scalar)
  [&]<int... J>(std::integer_sequence<int, J...>) {
    ((Eigen::Map<Eigen::Matrix<Scalar, n - J, 1>>(l + kernels::packed_col(n, J)) =
          Eigen::Map<const Eigen::Matrix<Scalar, n - J, 1>>(a + J * (n + 1))),
     ...);
  }
  (std::make_integer_sequence<int, n>{});
}

/// The products with the data of an OcpQp that every OCP backend needs (H v, A v, A' v, the
/// squared row norms) and the stage of a flat constraint index; the problem is referenced.
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
struct OcpProducts {
  using Problem = OcpQp<Scalar, N, NX, NU, NG, NGN>;
  static constexpr int NW = NX + NU;
  static constexpr int NV = Problem::nv;
  static constexpr int NA = Problem::na;
  using VecV = Eigen::Matrix<Scalar, NV, 1>;
  using VecA = Eigen::Matrix<Scalar, NA, 1>;

  const Problem* p = nullptr;  ///< referenced problem

  // With lazy_products (SIMD): products written per column, M v as one broadcast multiply-add
  // per column of M into a fixed-size accumulator and M' v as one dot product per (contiguous)
  // column of M: Eigen 3.4's lazy products of these shapes, and of their sums, took ~3x the
  // instructions (bench/qp/RESULTS.md: H x 16.5 k -> 5.5 k per call). Without SIMD: Eigen's
  // gemv.
  void hess_mul(const VecV& x, VecV& y) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const int o = k * NW;
      const auto xk = x.template segment<NX>(o);
      const auto uk = x.template segment<NU>(o + NX);
      if constexpr (lazy_products) {
        // columns of Q, S and R by broadcast multiply-adds; S' u as dot products of S's
        // (contiguous) columns with u
        Eigen::Matrix<Scalar, NX, 1> ax = s.Q.col(0) * xk(0);
        Eigen::Matrix<Scalar, NU, 1> au = s.S.col(0) * xk(0);
        for (int j = 1; j < NX; ++j) {
          ax += s.Q.col(j) * xk(j);
          au += s.S.col(j) * xk(j);
        }
        if constexpr (NU > 0) {
          for (int j = 0; j < NU; ++j)
            au += s.R.col(j) * uk(j);
        }
        Eigen::Matrix<Scalar, NX, 1> st;
        for (int i = 0; i < NX; ++i)
          st(i) = s.S.col(i).dot(uk);
        y.template segment<NX>(o) = ax + st;
        y.template segment<NU>(o + NX) = au;
      } else {
        y.template segment<NX>(o).noalias() = s.Q * xk;
        y.template segment<NX>(o).noalias() += s.S.transpose() * uk;
        y.template segment<NU>(o + NX).noalias() = s.S * xk;
        y.template segment<NU>(o + NX).noalias() += s.R * uk;
      }
    }
    if constexpr (lazy_products)
      y.template tail<NX>().noalias() = p->terminal.Q.lazyProduct(x.template tail<NX>());
    else
      y.template tail<NX>().noalias() = p->terminal.Q * x.template tail<NX>();
  }

  void cons_mul(const VecV& x, VecA& y) const {
    for (int k = 0; k < N; ++k) {
      const auto& s = p->stage[k];
      const int o = k * NW, r = k * (NX + NG);
      const auto xk = x.template segment<NX>(o);
      const auto uk = x.template segment<NU>(o + NX);
      if constexpr (lazy_products) {
        Eigen::Matrix<Scalar, NX, 1> ad = x.template segment<NX>(o + NW);
        Eigen::Matrix<Scalar, NG, 1> ag = s.C.col(0) * xk(0);
        ad -= s.A.col(0) * xk(0);
        for (int j = 1; j < NX; ++j) {
          ad -= s.A.col(j) * xk(j);
          ag += s.C.col(j) * xk(j);
        }
        if constexpr (NU > 0) {
          for (int j = 0; j < NU; ++j) {
            ad -= s.B.col(j) * uk(j);
            ag += s.D.col(j) * uk(j);
          }
        }
        y.template segment<NX>(r) = ad;
        y.template segment<NG>(r + NX) = ag;
      } else {
        auto dyn = y.template segment<NX>(r);
        dyn = x.template segment<NX>(o + NW);
        dyn.noalias() -= s.A * xk;
        dyn.noalias() -= s.B * uk;
        auto gen = y.template segment<NG>(r + NX);
        gen.noalias() = s.C * xk;
        gen.noalias() += s.D * uk;
      }
    }
    if constexpr (lazy_products)
      y.template tail<NGN>().noalias() = p->terminal.C.lazyProduct(x.template tail<NX>());
    else
      y.template tail<NGN>().noalias() = p->terminal.C * x.template tail<NX>();
  }

  void cons_tmul(const VecA& l, VecV& y) const {
    if constexpr (lazy_products)
      y.template tail<NX>().noalias() =
          p->terminal.C.transpose().lazyProduct(l.template tail<NGN>());
    else
      y.template tail<NX>().noalias() = p->terminal.C.transpose() * l.template tail<NGN>();
    for (int k = N - 1; k >= 0; --k) {
      const auto& s = p->stage[k];
      const int o = k * NW, r = k * (NX + NG);
      const auto ld = l.template segment<NX>(r);
      const auto lg = l.template segment<NG>(r + NX);
      y.template segment<NX>(o + NW) += ld;  // x_{k+1} (set by the previous pass)
      if constexpr (lazy_products) {
        Eigen::Matrix<Scalar, NX, 1> tx;
        Eigen::Matrix<Scalar, NU, 1> tu;
        for (int i = 0; i < NX; ++i)
          tx(i) = s.C.col(i).dot(lg) - s.A.col(i).dot(ld);
        if constexpr (NU > 0) {
          for (int i = 0; i < NU; ++i)
            tu(i) = s.D.col(i).dot(lg) - s.B.col(i).dot(ld);
        }
        y.template segment<NX>(o) = tx;
        y.template segment<NU>(o + NX) = tu;
      } else {
        auto yx = y.template segment<NX>(o);
        auto yu = y.template segment<NU>(o + NX);
        yx.noalias() = s.C.transpose() * lg;
        yx.noalias() -= s.A.transpose() * ld;
        yu.noalias() = s.D.transpose() * lg;
        yu.noalias() -= s.B.transpose() * ld;
      }
    }
  }

  static int stage_of(int i) {
    const int k = i < NV ? i / NW : (i - NV) / (NX + NG);
    return k < N ? k : N;
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
};

/// Block-elimination backend with rank-one updates for ActiveSetCore on an OcpQp (the default).
template <typename Scalar, int N, int NX, int NU, int NG, int NGN>
struct OcpBackend : OcpProducts<Scalar, N, NX, NU, NG, NGN> {
  using Products = OcpProducts<Scalar, N, NX, NU, NG, NGN>;
  using Products::p;
  using Products::stage_of;
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
  static constexpr int PW = kernels::packed_size(NW);  ///< scalars of a packed L_kk
  static constexpr int PX = kernels::packed_size(NX);  ///< scalars of the packed L_NN

  std::array<std::array<Scalar, PW>, N> l_diag;  ///< L_kk, packed lower triangle
  std::array<MatXW, N> l_off;                    ///< X_k = L_{k+1,k}, rows of x_{k+1}
  std::array<Scalar, PX> l_term;                 ///< L_NN, packed lower triangle
  int dirty_from = 0;                            ///< first stage to refactorize (N+1: none)
  int updates = 0;                          ///< rank-one updates since the last full factorization
  int updates_last = 0;                     ///< rank-one updates made by the last factorize()
  std::array<int, max_pending> pending{};   ///< changed constraints not yet in the factor
  int n_pending = 0;                        ///< how many
  std::array<std::int8_t, NZ> in_factor{};  ///< 1: constraint i is active in the factor
  Scalar w_ = 0;                            ///< bound weight of the factor
  Scalar delta_ = 0;                        ///< delta of the factor

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
    Scalar* y = b.data();
    for (int k = 0; k < N; ++k) {
      Scalar* v = y + k * NW;
      if (k > 0)
        sub_x_times(l_off[k - 1], y + (k - 1) * NW, v);
      solve_lower_packed<NW>(l_diag[k].data(), v);
    }
    Scalar* vx = y + N * NW;
    sub_x_times(l_off[N - 1], y + (N - 1) * NW, vx);
    solve_lower_packed<NX>(l_term.data(), vx);
    solve_lower_transposed_packed<NX>(l_term.data(), vx);
    for (int k = N - 1; k >= 0; --k) {
      Scalar* v = y + k * NW;
      const Scalar* z = y + (k + 1) * NW;
      Eigen::Map<VecW>(v).noalias() -= l_off[k].transpose() * Eigen::Map<const VecX>(z);
      solve_lower_transposed_packed<NW>(l_diag[k].data(), v);
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

  /// v(0:NX) -= X y (X: NX x NW, y: NW).
  static void sub_x_times(const MatXW& x, const Scalar* y, Scalar* v) {
    Eigen::Map<VecX>(v).noalias() -= x * Eigen::Map<const VecW>(y);
  }

  bool factor_stage(int k, const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
    using namespace kernels;
    const auto& s = p->stage[k];
    const int r0 = k * (NX + NG);
    MatW d;  // M_kk, then L_kk (full square scratch: the kernels write above the diagonal)
    d.template topLeftCorner<NX, NX>() = s.Q;
    d.template bottomLeftCorner<NU, NX>() = s.S;
    d.template topRightCorner<NX, NU>() = s.S.transpose();
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
    // X_k starts as -E [A B]; the E-weighted dynamics d += [A B]' E [A B] = -T X_k (lower),
    // with T = [A B]' (column i = row i of [A B])
    MatXW& x = l_off[k];
    Eigen::Matrix<Scalar, NW, NX> t;
    t.template topRows<NX>() = s.A.transpose();
    t.template bottomRows<NU>() = s.B.transpose();
    {
      Scalar wd[NX];
      for (int i = 0; i < NX; ++i)
        wd[i] = -wa(r0 + i);
      for (int c = 0; c < NX; ++c)
        for (int i = 0; i < NX; ++i)
          x(i, c) = wd[i] * s.A(i, c);
      for (int c = 0; c < NU; ++c)
        for (int i = 0; i < NX; ++i)
          x(i, NX + c) = wd[i] * s.B(i, c);
    }
    gemm_nt_lower<NW, NW, NW, 1, NX, NW, Update::subtract>(d.data(), t.data(), x.data(), NX);
    if (k > 0) {
      // x corner: + E_{k-1} - X_{k-1} X_{k-1}'
      const Scalar* wp = wa.data() + (k - 1) * (NX + NG);
      for (int c = 0; c < NX; ++c)
        d(c, c) += wp[c];
      const Scalar* xp = l_off[k - 1].data();
      gemm_nt_lower<NX, NX, NX, NX, 1, NW, Update::subtract>(d.data(), xp, xp, NW);
    }
    if (!potrf_lower<NW>(d.data()))
      return false;
    pack_lower<NW>(d.data(), l_diag[k].data());
    // X_k = -E [A B] L^-T
    trsm_rlt<NX, NW>(x.data(), d.data());
    return true;
  }

  bool factor_terminal(const ConstraintState* ws, Scalar delta, Scalar w, const VecA& wa) {
    using namespace kernels;
    const auto& t = p->terminal;
    MatX d = t.Q;
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
    const Scalar* xp = l_off[N - 1].data();
    gemm_nt_lower<NX, NX, NX, NX, 1, NX, Update::subtract>(d.data(), xp, xp, NW);
    if (!potrf_lower<NX>(d.data()))
      return false;
    pack_lower<NX>(d.data(), l_term.data());
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
        if (!rotate_packed_column<NW, NX>(ld, lo + j * NX, v.data(), vx.data(), j, sigma, tol))
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
      if (!rotate_packed_column<NX, 0>(ld, nullptr, vx.data(), nullptr, j, sigma, tol))
        return false;
    }
    return true;
  }
};

}  // namespace arbor::qp::detail
