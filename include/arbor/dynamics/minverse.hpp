// arbor: M(q)^-1 by the ABA-based recursion (Carpentier & Mansard 2018), never by inverting M.
// The per-body 6 x nv work blocks hold, column k, the response to a unit torque at joint k:
// first the articulated bias forces (leaves to root), then the accelerations (root to leaves).
// Blocks are row-major and transformed a whole block of columns at a time (rows are contiguous,
// so the sparse per-body actions vectorize across columns).
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/aba.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/model/topology.hpp"

namespace arbor {

namespace detail {

/// minverse's backward pass: columns [i, last] (the subtree of i) of the bias-force blocks, the
/// articulated inertias, and rows i of M^-1 over the subtree. WithPayload: the payload's inertia
/// added to its body's articulated inertia.
template <class R, bool WithPayload, class Scalar>
ARBOR_INLINE void minverse_backward(Data<R, Scalar>& d) {
  constexpr int n = R::nv;
  constexpr bool flat = std::is_floating_point_v<Scalar>;  // per-body passes flattened
  static_for_reverse_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    constexpr int L = model::subtree_last<R>(i) - i + 1;
    using Row = Eigen::Matrix<Scalar, 1, L>;
    const Scalar Dinv = art_body_start<R, i, WithPayload>(d);
    auto blk = d.Fminv[i].template middleCols<L>(i);
    Row mrow = B::ST(spatial::rows_of<0>(blk), spatial::rows_of<3>(blk)) * Scalar(-Dinv);
    mrow[0] = Dinv;  // column i: the unit torque at i itself (no bias force from below)
    d.Minv.row(i).template segment<L>(i) = mrow;
    if constexpr (i + L < n)
      d.Minv.row(i).template tail<n - i - L>().setZero();
    if constexpr (B::parent >= 0) {
      constexpr int p = B::parent;
      using Init = std::conditional_t<last_child<R>(p) == i, spatial::BodyOps<R, p, Scalar>, void>;
      B::template add_art_projection<Init>(d.joint[i], d.Yaba[i], d.U[i], Dinv, d.Yaba[p]);
      Row f[3], t[3];
      for (int j = 0; j < 3; ++j) {
        f[j] = blk.row(j) + mrow * d.U[i].f[j];
        t[j] = blk.row(3 + j) + mrow * d.U[i].n[j];
      }
      auto pb = d.Fminv[p].template middleCols<L>(i);
      B::template force_to_parent<true>(d.joint[i], f, t, spatial::rows_of<0>(pb),
                                        spatial::rows_of<3>(pb));
    }
  });
}

/// minverse_backward with the payload, out of line (called only when one is set).
template <class R, class Scalar>
ARBOR_NOINLINE void minverse_backward_payload(Data<R, Scalar>& d) {
  minverse_backward<R, true>(d);
}

}  // namespace detail

/// M(q)^-1 (full symmetric) in data.Minv; returns it.
template <Robot R, class Scalar, class Q>
const typename Data<R, Scalar>::Matrix& minverse(Data<R, Scalar>& d,
                                                 const Eigen::MatrixBase<Q>& q) {
  static_assert(Q::RowsAtCompileTime == R::nq, "q has the wrong size");
  constexpr int n = R::nv;
  constexpr bool flat = std::is_floating_point_v<Scalar>;  // per-body passes flattened
  detail::joint_states(d, q);
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    constexpr int last = model::subtree_last<R>(i);
    d.Fminv[i].template middleCols<last - i + 1>(i).setZero();
  });
  // Backward pass: columns [i, last] (the subtree of i) of the bias-force blocks; with a payload,
  // its second instantiation (detail::minverse_backward), out of line: the plain path keeps the
  // inlining budget it had without the feature.
  if (d.payload.active)
    detail::minverse_backward_payload<R>(d);
  else
    detail::minverse_backward<R, false>(d);
  // Forward pass: rows i, columns [i, n) of M^-1 and of the acceleration blocks.
  static_for_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    constexpr int L = n - i;
    using Row = Eigen::Matrix<Scalar, 1, L>;
    Row mrow = d.Minv.row(i).template tail<L>();
    Row v[3], w[3];
    if constexpr (B::parent >= 0) {
      const auto pb = d.Fminv[B::parent].template middleCols<L>(i);
      B::motion_to_child(d.joint[i], spatial::rows_of<0>(pb), spatial::rows_of<3>(pb), v, w);
      Row ua = v[0] * d.U[i].f[0];
      for (int j = 1; j < 3; ++j)
        ua += v[j] * d.U[i].f[j];
      for (int j = 0; j < 3; ++j)
        ua += w[j] * d.U[i].n[j];
      mrow -= ua * d.Dinv[i];
    } else {
      for (int j = 0; j < 3; ++j) {
        v[j].setZero();
        w[j].setZero();
      }
    }
    B::add_S(v, w, mrow);
    d.Minv.row(i).template tail<L>() = mrow;
    auto blk = d.Fminv[i].template middleCols<L>(i);
    for (int j = 0; j < 3; ++j) {
      blk.row(j) = v[j];
      blk.row(3 + j) = w[j];
    }
  });
  for (int c = 0; c < n; ++c)
    for (int r = c + 1; r < n; ++r)
      d.Minv(r, c) = d.Minv(c, r);
  return d.Minv;
}

namespace detail {

/// Depth of body i (0 for a root) and its ancestors, nearest first (compile time).
template <class R>
constexpr int tree_depth(int i) {
  int d = 0;
  for (int j = R::parent[i]; j >= 0; j = R::parent[j])
    ++d;
  return d;
}
template <class R>
constexpr int ancestor(int i, int t) {  // t = 0: the parent
  int j = R::parent[i];
  for (; t > 0; --t)
    j = R::parent[j];
  return j;
}

/// M^-1 from a given M (full symmetric) by the tree-structured factorisation M = L' D L
/// (Featherstone's LTDL: L unit lower triangular, nonzero only at (k, i) with joint i an ancestor
/// of k, so no fill-in for any tree), then W = L^-1 (same sparsity) column by column, and
/// M^-1 = W D^-1 W' as rank-1 updates dinv_c w_c w_c' over the subtree block of each joint c.
/// O(n d^2) for the factor, O(sum of subtree sizes squared) for the rest; no square roots (any
/// Scalar); needs every subtree's columns contiguous (depth-first numbering). H is scratch.
/// Used by the derivative sweeps, which form M anyway (aba_derivatives); on its own, minverse's
/// articulated-body recursion above needs no M.
template <class R, class Scalar>
ARBOR_INLINE void minverse_from_mass_matrix(const MatN<Scalar, R::nv>& M, MatN<Scalar, R::nv>& H,
                                            MatN<Scalar, R::nv>& Minv) {
  constexpr int n = R::nv;
  H = M;
  // Factor, leaves to root: D in the diagonal of H, L below it (ancestors' columns only).
  static_for_reverse<n>([&](auto K) {
    constexpr int k = decltype(K)::value;
    constexpr int dk = tree_depth<R>(k);
    if constexpr (dk > 0) {
      const Scalar dk_inv = Scalar(1) / H(k, k);
      static_for<dk>([&](auto T) {
        constexpr int i = ancestor<R>(k, decltype(T)::value);
        constexpr int di = tree_depth<R>(i);
        const Scalar a = H(k, i) * dk_inv;
        H(i, i) -= H(k, i) * a;
        static_for<di>([&](auto U) {
          constexpr int j = ancestor<R>(i, decltype(U)::value);
          H(i, j) -= H(k, j) * a;
        });
        H(k, i) = a;
      });
    }
  });
  // W = L^-1 in place of L, column by column from the root (column c needs the columns m > c of
  // L, not yet overwritten): w = e_c, then for m in the subtree of c in order, the rows of the
  // strict subtree of m lose L(., m) w_m.
  static_for<n>([&](auto C) {
    constexpr int c = decltype(C)::value;
    constexpr int Lc = model::subtree_last<R>(c) - c;  // strict subtree size
    if constexpr (Lc > 0) {
      Eigen::Matrix<Scalar, Lc, 1> w = -H.col(c).template segment<Lc>(c + 1);
      static_for<Lc>([&](auto M_) {
        constexpr int m = c + 1 + decltype(M_)::value;
        constexpr int Lm = model::subtree_last<R>(m) - m;
        if constexpr (Lm > 0)
          w.template segment<Lm>(m + 1 - c - 1) -=
              H.col(m).template segment<Lm>(m + 1) * w[m - c - 1];
      });
      H.col(c).template segment<Lc>(c + 1) = w;
    }
  });
  // M^-1 = sum over c of dinv_c w_c w_c', w_c = (1, W(c+1.., c)) over the subtree block of c.
  Minv.setZero();
  static_for<n>([&](auto C) {
    constexpr int c = decltype(C)::value;
    constexpr int Lc = model::subtree_last<R>(c) - c + 1;
    const Scalar dinv = Scalar(1) / H(c, c);
    Eigen::Matrix<Scalar, Lc, 1> w;
    w[0] = Scalar(1);
    if constexpr (Lc > 1)
      w.template tail<Lc - 1>() = H.col(c).template segment<Lc - 1>(c + 1);
    Minv.template block<Lc, Lc>(c, c).noalias() += (w * dinv) * w.transpose();
  });
}

}  // namespace detail

}  // namespace arbor
