// arbor: composite rigid-body algorithm (joint-space inertia matrix M(q), full symmetric).
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/payload.hpp"
#include "arbor/model/topology.hpp"

namespace arbor {

namespace detail {

/// Carries the force F = Ycrb_i S_i (expressed in body j) up the ancestors of i, filling M(p, i).
template <class R, int i, int j, class Scalar>
ARBOR_INLINE void crba_up(Data<R, Scalar>& d, const Force<Scalar>& F) {
  using Bj = spatial::BodyOps<R, j, Scalar>;
  if constexpr (Bj::parent >= 0) {
    constexpr int p = Bj::parent;
    using Bp = spatial::BodyOps<R, p, Scalar>;
    const Force<Scalar> Fp = Bj::force_to_parent(d.joint[j], F);
    const Scalar m = Bp::ST(Fp);
    d.M(p, i) = m;
    d.M(i, p) = m;
    crba_up<R, i, p>(d, Fp);
  }
}

/// When the largest tree below one root joint has fewer bodies than this, crba carries each
/// column up the tree on its own (fewer instructions for short chains); from it on, whole blocks
/// of columns at once (vectorized across columns). Judged by the largest tree, not by nv: the
/// YuMi's two 7-joint arms (nv = 14) take 4966 instructions column by column against 6788 in
/// blocks; the Atlas's 18-body torso tree stays blocked (15389 against 17125), bench/RESULTS.md.
inline constexpr int kCrbaBlockFrom = 12;

/// Ycrb S for a rigid (composite) inertia and the motion subspace of body i.
template <class B, class Scalar>
ARBOR_INLINE Force<Scalar> inertia_S(const Inertia<Scalar>& Y) {
  if constexpr (B::aligned) {
    constexpr int k = B::k;
    Force<Scalar> F;
    if constexpr (B::revolute) {
      // f = -h x (sign e_k) = sign (e_k x h); n = sign Io e_k
      F.f[k] = Scalar(0);
      F.f[B::ib] = Y.h[B::ia];
      F.f[B::ia] = -Y.h[B::ib];
      F.n = Y.Io.col(k);
      if constexpr (B::sign < 0) {
        F.f = -F.f;
        F.n = -F.n;
      }
    } else {
      F.f.setZero();
      F.f[k] = Y.m * Scalar(B::sign);
      // n = h x (sign e_k) = sign (h_b e_a - h_a e_b)
      F.n[k] = Scalar(0);
      F.n[B::ia] = Y.h[B::ib];
      F.n[B::ib] = -Y.h[B::ia];
      if constexpr (B::sign < 0)
        F.n = -F.n;
    }
    return F;
  } else {
    return Y * B::S_times(Scalar(1));
  }
}

}  // namespace detail

namespace detail {

/// crba for small trees: each column Ycrb_i S_i carried up the ancestors of i on its own.
template <class R, class Scalar, class Q>
ARBOR_INLINE void crba_columns(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q) {
  detail::joint_states(d, q);
  d.M.setZero();
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    d.Ycrb[i] = spatial::BodyOps<R, i, Scalar>::inertia();
  });
  if (d.payload.active)
    d.Ycrb[d.payload.body] += d.payload.Y;
  static_for_reverse<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    const Force<Scalar> F = detail::inertia_S<B>(d.Ycrb[i]);
    d.M(i, i) = B::ST(F);
    detail::crba_up<R, i, i>(d, F);
    if constexpr (B::parent >= 0)
      d.Ycrb[B::parent] += B::inertia_to_parent(d.joint[i], d.Ycrb[i]);
  });
}

/// crba for larger trees: the forces Ycrb_j S_j of the subtree of i are carried to each
/// ancestor as one row-major block of columns (data.Fminv), one sparse transform for all. Bodies
/// of the forest's small trees (below kCrbaBlockFrom bodies: the Atlas's legs beside its torso)
/// carry their own column as crba_columns does.
template <class R, class Scalar, class Q>
ARBOR_INLINE void crba_blocks(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q) {
  constexpr int n = R::nv;
  detail::joint_states(d, q);
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    d.Ycrb[i] = spatial::BodyOps<R, i, Scalar>::inertia();
    constexpr int last = model::subtree_last<R>(i);
    if constexpr (model::root_tree_size<R>(i) >= kCrbaBlockFrom)
      d.Fminv[i].template middleCols<last - i + 1>(i).setZero();
  });
  if (d.payload.active)
    d.Ycrb[d.payload.body] += d.payload.Y;
  static_for_reverse<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    constexpr int L = model::subtree_last<R>(i) - i + 1;
    if constexpr (model::root_tree_size<R>(i) < kCrbaBlockFrom) {
      // a small tree: this column up the ancestors (M(i, j), j in i's subtree, came from j's)
      const Force<Scalar> F = detail::inertia_S<B>(d.Ycrb[i]);
      d.M(i, i) = B::ST(F);
      detail::crba_up<R, i, i>(d, F);
      if constexpr (i + L < n) {
        d.M.row(i).template tail<n - i - L>().setZero();
        d.M.col(i).template tail<n - i - L>().setZero();
      }
      if constexpr (B::parent >= 0)
        d.Ycrb[B::parent] += B::inertia_to_parent(d.joint[i], d.Ycrb[i]);
      return;
    }
    using Row = Eigen::Matrix<Scalar, 1, L>;
    auto blk = d.Fminv[i].template middleCols<L>(i);
    const Force<Scalar> F = detail::inertia_S<B>(d.Ycrb[i]);
    for (int j = 0; j < 3; ++j) {
      blk(j, 0) = F.f[j];
      blk(3 + j, 0) = F.n[j];
    }
    const Row mrow = B::ST(spatial::rows_of<0>(blk), spatial::rows_of<3>(blk));
    d.M.row(i).template segment<L>(i) = mrow;
    d.M.col(i).template segment<L>(i) = mrow.transpose();
    if constexpr (i + L < n) {
      d.M.row(i).template tail<n - i - L>().setZero();
      d.M.col(i).template tail<n - i - L>().setZero();
    }
    if constexpr (B::parent >= 0) {
      auto pb = d.Fminv[B::parent].template middleCols<L>(i);
      B::template force_to_parent<true>(d.joint[i], spatial::rows_of<0>(blk),
                                        spatial::rows_of<3>(blk), spatial::rows_of<0>(pb),
                                        spatial::rows_of<3>(pb));
      d.Ycrb[B::parent] += B::inertia_to_parent(d.joint[i], d.Ycrb[i]);
    }
  });
}

}  // namespace detail

/// Joint-space inertia matrix M(q) (full symmetric) in data.M; returns it.
template <Robot R, class Scalar, class Q>
const typename Data<R, Scalar>::Matrix& crba(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q) {
  static_assert(Q::RowsAtCompileTime == R::nq, "q has the wrong size");
  if constexpr (model::largest_root_tree<R>() < detail::kCrbaBlockFrom)
    detail::crba_columns(d, q);
  else
    detail::crba_blocks(d, q);
  return d.M;
}

}  // namespace arbor
