// arbor: first-order analytical derivatives of inverse dynamics, d tau / d q, d tau / d v and
// d tau / d a = M, after Carpentier & Mansard (RSS 2018), in the compact world-frame form of
// their recursion (the same identities as IDSVA, Singh, Russell & Wensing, RA-L 2022).
//
// Everything below is in the world frame. For joint j with world column S_j, parent velocity
// v_p and parent acceleration a_p (gravity included as a base acceleration -g):
//   dS_j  = v_p x S_j,                ddS_j = a_p x S_j + v_p x dS_j,
// and over the subtree of j the composite inertia Y_j, its rate Yd_j = sum (v_i x* Y_i - Y_i v_i x)
// (a zero-mass rigid-inertia shape), the composite momentum h_j and the net force F_j. Then, with
//   P_j = Y_j S_j,   Q_j = Yd_j S_j - S_j x* h_j,
//   G_j = S_j x* F_j + Y_j ddS_j + Yd_j dS_j + dS_j x* h_j,
//   H_j = 2 Y_j dS_j + Yd_j S_j + S_j x* h_j,
// for k an ancestor of j or j itself, and for j a strict ancestor of k:
//   d tau_k / d q_j = S_k . G_j,      d tau_j / d q_k = P_j . ddS_k + Q_j . dS_k,
//   d tau_k / d v_j = S_k . H_j,      d tau_j / d v_k = 2 P_j . dS_k + Q_j . S_k,
//   M_kj = S_k . P_j,
// and zero for pairs of joints on different branches. Per joint the cost is constant; the pair
// sums run over each joint's subtree, whose columns are contiguous (depth-first numbering), as
// row-vector operations across those columns: O(n d) for a tree of depth d.
//
// Cost (bench/RESULTS.md): per body, about 300 multiply-adds in the forward pass
// (placement, column, dS, ddS, world inertia, its rate, momentum and force) and 250 in the
// backward pass (P, Q, G, H and the composite sums), plus 42 per pair of joints on one branch. The
// spatial products are written out scalar by scalar (namespace sx) and force-inlined: through
// Eigen's vectorised 3-vector cross products, comma initialisers and the out-of-line
// Inertia * Motion, GCC spends about twice the arithmetic in shuffles, calls and copies. A root
// joint's world column is a compile-time constant (RootColumn) and its dS is zero: its products
// and its row, the longest, skip the structural zeros. Instructions per call from a user's
// translation unit (with the batched sines and cosines and the scalar world placements of
// dynamics/): iiwa7 7 631, Kinova Gen3 7 931, YuMi 15 797 (Pinocchio 3.7.0: 24 658, 24 041,
// 48 599).
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/derivatives/derivative_data.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/jacobian.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/minverse.hpp"
#include "arbor/dynamics/payload.hpp"
#include "arbor/dynamics/rnea.hpp"
#include "arbor/spatial/sx.hpp"

namespace arbor {

namespace detail {

/// World-frame quantities of the constant body inertia of body i.
template <class R, int i, class Scalar>
struct WorldInertia {
  static constexpr const model::Inertia& In = R::body_inertia[i];
  static constexpr bool massless = In.mass == 0.0;
  struct Com {
    static constexpr double at(int j) { return In.com[j]; }
  };
  struct Ic {
    static constexpr double at(int r, int c) { return In.I[r][c]; }
  };

  /// The inertia of body i in the world frame, from its placement oMi.
  ARBOR_INLINE static Inertia<Scalar> of(const SE3<Scalar>& X) {
    Inertia<Scalar> Y;
    const Scalar m = Scalar(In.mass);
    Y.m = m;
    Vec3<Scalar> c = X.p;
    if constexpr (!spatial::cst::is_zero_vec<Com>())
      c += spatial::cst::mat_cvec<Scalar, Com>(X.R);
    Y.h = c * m;
    // Io = R Ic R^T + m (|c|^2 1 - c c^T)
    const Mat3<Scalar> T = spatial::cst::mul_cols<Scalar, Ic, 3>(X.R);  // R Ic
    const Scalar cc = c.squaredNorm();
    for (int r = 0; r < 3; ++r)
      for (int k = r; k < 3; ++k) {
        Scalar e = T.row(r).dot(X.R.row(k)) - Y.h[r] * c[k];
        if (r == k)
          e += m * cc;
        Y.Io(r, k) = e;
        Y.Io(k, r) = e;
      }
    return Y;
  }

  /// Rate v x* Y - Y v x of a rigid inertia Y moving with velocity v.
  ARBOR_INLINE static spatial::InertiaRate<Scalar> rate(const Inertia<Scalar>& Y,
                                                        const Motion<Scalar>& v) {
    spatial::InertiaRate<Scalar> D;
    D.hd = v.v * Y.m + v.w.cross(Y.h);
    // Iod = [w] Io - Io [w] - (h v^T + v h^T - 2 (v . h) 1) = A + A^T - ..., A = [w] Io
    Mat3<Scalar> A;
    for (int k = 0; k < 3; ++k)
      A.col(k) = v.w.cross(Y.Io.col(k));
    const Scalar vh2 = Scalar(2) * v.v.dot(Y.h);
    for (int r = 0; r < 3; ++r)
      for (int k = r; k < 3; ++k) {
        Scalar e = A(r, k) + A(k, r) - Y.h[r] * v.v[k] - v.v[r] * Y.h[k];
        if (r == k)
          e += vh2;
        D.Iod(r, k) = e;
        D.Iod(k, r) = e;
      }
    return D;
  }
};

/// m x S for the world column S of body B's joint (no angular part for prismatic joints).
template <class B, class Scalar>
ARBOR_INLINE Motion<Scalar> cross_col(const Motion<Scalar>& m, const Motion<Scalar>& Sc) {
  if constexpr (B::revolute)
    return spatial::cross(m, Sc);
  else
    return {m.w.cross(Sc.v), Vec3<Scalar>::Zero()};
}

/// Force cross product S x* f for the world column S of body B's joint.
template <class B, class Scalar>
ARBOR_INLINE Force<Scalar> cross_col_force(const Motion<Scalar>& Sc, const Force<Scalar>& f) {
  if constexpr (B::revolute)
    return spatial::cross(Sc, f);
  else
    return {Vec3<Scalar>::Zero(), Sc.v.cross(f.f)};
}

/// The row vector sum_c x[c] * blk.row(c).segment<L>(from) (x a 6-vector given as two 3-vectors).
template <int L, class Scalar, class Blk>
ARBOR_INLINE Eigen::Matrix<Scalar, 1, L> row_dot(const Blk& blk, int from, const Vec3<Scalar>& x0,
                                                 const Vec3<Scalar>& x1) {
  Eigen::Matrix<Scalar, 1, L> r = blk.row(0).template segment<L>(from) * x0[0];
  for (int c = 1; c < 3; ++c)
    r += blk.row(c).template segment<L>(from) * x0[c];
  for (int c = 0; c < 3; ++c)
    r += blk.row(3 + c).template segment<L>(from) * x1[c];
  return r;
}

/// World-frame column oMi S_i of joint i (detail::world_column with the scalar cross product).
template <class R, int i, class Scalar>
ARBOR_INLINE Motion<Scalar> world_column_sx(const Data<R, Scalar>& d) {
  using B = spatial::BodyOps<R, i, Scalar>;
  const SE3<Scalar>& o = d.oMi[i];
  Vec3<Scalar> axis;
  if constexpr (B::aligned)
    axis = (B::sign > 0) ? Vec3<Scalar>(o.R.col(B::k)) : Vec3<Scalar>(-o.R.col(B::k));
  else
    axis = spatial::cst::mat_cvec<Scalar, typename B::AxisV>(o.R);
  if constexpr (B::revolute)
    return {sx::cross(o.p, axis), axis};
  else
    return {axis, Vec3<Scalar>::Zero()};
}

/// row_dot with the angular half of x zero: sum_c x0[c] * blk.row(c).segment<L>(from).
template <int L, class Scalar, class Blk>
ARBOR_INLINE Eigen::Matrix<Scalar, 1, L> row_dot3(const Blk& blk, int from,
                                                  const Vec3<Scalar>& x0) {
  Eigen::Matrix<Scalar, 1, L> r = blk.row(0).template segment<L>(from) * x0[0];
  for (int c = 1; c < 3; ++c)
    r += blk.row(c).template segment<L>(from) * x0[c];
  return r;
}

/// The world column of a root joint, a constant: its placement oMi = Pl Rj(q) leaves the joint
/// axis Pl.R a and the joint origin Pl.p where they are, so S = (Pl.p x Pl.R a, Pl.R a) for a
/// revolute joint and (Pl.R a, 0) for a prismatic one. Kv, Kw: its halves as constant vectors.
template <class R, int i>
struct RootColumn {
  static constexpr const model::Placement& X = R::joint_placement[i];
  static constexpr bool revolute = model::is_revolute(R::joint_kind[i]);
  static constexpr double axis(int r) {
    return X.R[r][0] * R::joint_axis[i][0] + X.R[r][1] * R::joint_axis[i][1] +
           X.R[r][2] * R::joint_axis[i][2];
  }
  static constexpr double at(int c) {  // (v; w)
    if (!revolute)
      return c < 3 ? axis(c) : 0.0;
    if (c >= 3)
      return axis(c - 3);
    return X.p[(c + 1) % 3] * axis((c + 2) % 3) - X.p[(c + 2) % 3] * axis((c + 1) % 3);
  }
  struct Kv {
    static constexpr double at(int c) { return RootColumn::at(c); }
  };
  struct Kw {
    static constexpr double at(int c) { return RootColumn::at(3 + c); }
  };
};

namespace sx {

/// K . x for a constant 3-vector K.
template <class S, class K>
ARBOR_INLINE S kdot(const Vec3<S>& x) {
  namespace c = spatial::cst;
  return c::dot3<S, c::VEntry<K, 0>, c::VEntry<K, 1>, c::VEntry<K, 2>>(x[0], x[1], x[2],
                                                                       [] { return S(0); });
}

/// K x x for a constant 3-vector K.
template <class S, class K>
ARBOR_INLINE Vec3<S> kcross(const Vec3<S>& x) {
  return spatial::cst::mul<S, spatial::cst::Skew<K>>(x);
}

/// a + b, either possibly a structural zero (Za, Zb).
template <bool Za, bool Zb, class S>
ARBOR_INLINE Vec3<S> add(const Vec3<S>& a, const Vec3<S>& b) {
  if constexpr (Za)
    return b;
  else if constexpr (Zb)
    return a;
  else
    return a + b;
}

}  // namespace sx

/// Row vector sum_c K[c] * blk.row(c).segment<L>(from) for a constant 6-vector K (zeros skipped).
template <int L, class Scalar, class K, class Blk>
ARBOR_INLINE Eigen::Matrix<Scalar, 1, L> row_dot_k(const Blk& blk, int from) {
  namespace c = spatial::cst;
  using T = Eigen::Matrix<Scalar, 1, L>;
  const auto r = [&](int k) { return blk.row(k).template segment<L>(from); };
  return c::dot_n<Scalar, c::VEntry<K, 0>, c::VEntry<K, 1>, c::VEntry<K, 2>, c::VEntry<K, 3>,
                  c::VEntry<K, 4>, c::VEntry<K, 5>>([] { return T(T::Zero()); }, T(r(0)), T(r(1)),
                                                    T(r(2)), T(r(3)), T(r(4)), T(r(5)));
}

/// Forward pass of the derivative sweep for body i, the part independent of the joint
/// accelerations: placement, world column (into data.J), velocity, dS, the body's own inertia,
/// rate and momentum (the start of the composite sums), and its force without the joint
/// accelerations, v x* h - fext (in data.of).
template <class R, int i, bool HasFext, class Scalar, class V>
ARBOR_INLINE void deriv_forward_velocity(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd,
                                         const Eigen::MatrixBase<V>& v,
                                         const typename Data<R, Scalar>::ForceArray* fext) {
  using B = spatial::BodyOps<R, i, Scalar>;
  using W = WorldInertia<R, i, Scalar>;
  body_placement<R, i, Scalar>(d);
  const Motion<Scalar> Sc = world_column_sx<R, i, Scalar>(d);
  for (int c = 0; c < 3; ++c) {
    d.J(c, i) = Sc.v[c];
    d.J(3 + c, i) = Sc.w[c];
  }
  const Scalar vi = Scalar(v[i]);
  if constexpr (B::parent < 0) {
    dd.dS[i] = Motion<Scalar>::Zero();
    dd.ov[i] = Sc * vi;
  } else {
    const Motion<Scalar>& vp = dd.ov[B::parent];
    dd.dS[i] = sx::cross_col<B>(vp, Sc);
    dd.ov[i] = vp + Sc * vi;
  }
  if constexpr (W::massless) {
    dd.oYcrb[i] = Inertia<Scalar>::Zero();
    dd.oYdot[i] = spatial::InertiaRate<Scalar>::Zero();
    dd.oh[i] = Force<Scalar>::Zero();
    dd.of[i] = Force<Scalar>::Zero();
  } else {
    dd.oYcrb[i] = W::of(d.oMi[i]);
    dd.oh[i] = sx::imul(dd.oYcrb[i], dd.ov[i]);
    dd.of[i] = sx::fcross(dd.ov[i], dd.oh[i]);
    dd.oYdot[i] = sx::rate(dd.oYcrb[i], dd.ov[i]);
  }
  if constexpr (HasFext)
    dd.of[i] -= d.oMi[i].act((*fext)[i]);
}

/// Forward pass of the derivative sweep for body i, the acceleration part: data.oa, ddS, and the
/// inertial force Y a added to data.of. a is the joint acceleration vector.
template <class R, int i, class Scalar, class V, class A>
ARBOR_INLINE void deriv_forward_acceleration(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd,
                                             const Eigen::MatrixBase<V>& v,
                                             const Eigen::MatrixBase<A>& a, const Vec3<Scalar>& g) {
  using B = spatial::BodyOps<R, i, Scalar>;
  const Motion<Scalar> Sc = sx::jcol<Scalar>(d.J, i);
  const Scalar ai = Scalar(a[i]);
  if constexpr (B::parent < 0) {
    // v_p = 0, a_p = (-g, 0): ddS = (-g) x S = [-g x S.w; 0]
    if constexpr (B::revolute)
      dd.ddS[i] = {sx::cross(Sc.w, g), Vec3<Scalar>::Zero()};
    else
      dd.ddS[i] = Motion<Scalar>::Zero();
    dd.oa[i] = {Sc.v * ai - g, Sc.w * ai};
  } else {
    constexpr int p = B::parent;
    const Motion<Scalar>& ap = dd.oa[p];
    const Motion<Scalar>& vp = dd.ov[p];
    const Motion<Scalar>& dS = dd.dS[i];
    if constexpr (B::revolute)
      dd.ddS[i] = {sx::cross2(ap.w, Sc.v, ap.v, Sc.w) + sx::cross2(vp.w, dS.v, vp.v, dS.w),
                   sx::cross2(ap.w, Sc.w, vp.w, dS.w)};
    else  // dS.w = 0
      dd.ddS[i] = {sx::cross2(ap.w, Sc.v, vp.w, dS.v), Vec3<Scalar>::Zero()};
    dd.oa[i] = ap + dS * Scalar(v[i]) + Sc * ai;
  }
  if constexpr (!WorldInertia<R, i, Scalar>::massless)
    dd.of[i] += sx::imul(dd.oYcrb[i], dd.oa[i]);
}

/// A payload's terms in the world-frame forward pass, added to its body's after the pass: the
/// world inertia Yp (composite start), its rate, momentum Yp v and force Yp a + v x* Yp v. Out of
/// line: the plain path keeps the inlining budget it had without the feature.
template <class R, class Scalar>
ARBOR_NOINLINE void deriv_forward_payload(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd) {
  const int b = d.payload.body;
  const Inertia<Scalar> Yp = payload_world(d);
  const Force<Scalar> hp = sx::imul(Yp, dd.ov[b]);
  sx::add_to(dd.oYcrb[b], Yp);
  sx::add_to(dd.oYdot[b], sx::rate(Yp, dd.ov[b]));
  sx::add_to(dd.oh[b], hp);
  sx::add_to(dd.of[b], sx::fcross(dd.ov[b], hp));
  sx::add_to(dd.of[b], sx::imul(Yp, dd.oa[b]));
}

/// Backward pass of the derivative sweep for body i: tau_i, the columns P, Q, G, H of joint i,
/// the rows and columns of the derivative matrices over the subtree of i, and the composite sums
/// handed to the parent. Fused (aba_derivatives' fused sweep): the composite inertia is already
/// in data.Ycrb and its column P in deriv.dP (from the pass that formed M), so neither is redone.
template <class R, int i, bool WithM, class Scalar, bool Fused = false>
ARBOR_INLINE void deriv_backward_body(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd) {
  using B = spatial::BodyOps<R, i, Scalar>;
  constexpr int n = R::nv;
  constexpr int last = model::subtree_last<R>(i);
  constexpr int L = last - i + 1;
  const Motion<Scalar> Sc = sx::jcol<Scalar>(d.J, i);
  const Motion<Scalar>& dS = dd.dS[i];
  const Inertia<Scalar>& Y = Fused ? d.Ycrb[i] : dd.oYcrb[i];
  const spatial::InertiaRate<Scalar>& Yd = dd.oYdot[i];
  const Force<Scalar>& h = dd.oh[i];
  const Force<Scalar>& F = dd.of[i];

  // A root joint: S constant (RootColumn), dS = 0 and ddS = ((-g) x S, 0)
  // (deriv_forward_velocity, _acceleration); its products skip the structural zeros of S.
  constexpr bool root = B::parent < 0;
  using K = RootColumn<R, i>;
  using Kv = typename K::Kv;
  using Kw = typename K::Kw;
  constexpr bool kv0 = spatial::cst::is_zero_vec<Kv>(), kw0 = spatial::cst::is_zero_vec<Kw>();
  Force<Scalar> Q, G, H;
  Motion<Scalar> dS2;
  if constexpr (root) {
    d.tau[i] = sx::kdot<Scalar, Kv>(F.f) + sx::kdot<Scalar, Kw>(F.n);
    // Yd S = (Kw x hd, Iod Kw - Kv x hd), S x* f = (Kw x f.f, Kw x f.n + Kv x f.f)
    Force<Scalar> YdS, Sxh, SxF;
    YdS.f = sx::kcross<Scalar, Kw>(Yd.hd);
    YdS.n = spatial::cst::mat_cvec<Scalar, Kw>(Yd.Iod) - sx::kcross<Scalar, Kv>(Yd.hd);
    Sxh.f = sx::kcross<Scalar, Kw>(h.f);
    Sxh.n = sx::add<kw0, kv0>(sx::kcross<Scalar, Kw>(h.n), sx::kcross<Scalar, Kv>(h.f));
    SxF.f = sx::kcross<Scalar, Kw>(F.f);
    SxF.n = sx::add<kw0, kv0>(sx::kcross<Scalar, Kw>(F.n), sx::kcross<Scalar, Kv>(F.f));
    Q = YdS - Sxh;
    const Vec3<Scalar>& a = dd.ddS[i].v;  // Y (a, 0) = (m a, h x a)
    G = {SxF.f + a * Y.m, SxF.n + sx::cross(Y.h, a)};
    H = YdS + Sxh;
    dS2 = Motion<Scalar>::Zero();
  } else {
    d.tau[i] = sx::dot(F, Sc);
    const Force<Scalar> YdS = sx::rmul(Yd, Sc);
    const Force<Scalar> Sxh = sx::cross_col_force<B>(Sc, h);
    Q = YdS - Sxh;
    G = sx::cross_col_force<B>(Sc, F) + sx::imul(Y, dd.ddS[i]) + sx::rmul(Yd, dS) +
        sx::fcross(dS, h);
    dS2 = dS * Scalar(2);
    H = sx::imul(Y, dS2) + YdS + Sxh;
  }
  if constexpr (!Fused) {
    Force<Scalar> P;
    if constexpr (root) {  // Y S = (m Kv + Kw x h, Io Kw - Kv x h)
      P.f = sx::add<kv0, kw0>(
          Vec3<Scalar>(Scalar(Kv::at(0)) * Y.m, Scalar(Kv::at(1)) * Y.m, Scalar(Kv::at(2)) * Y.m),
          sx::kcross<Scalar, Kw>(Y.h));
      P.n = spatial::cst::mat_cvec<Scalar, Kw>(Y.Io) - sx::kcross<Scalar, Kv>(Y.h);
    } else {
      P = sx::imul(Y, Sc);
    }
    for (int c = 0; c < 3; ++c) {
      dd.dP(c, i) = P.f[c];
      dd.dP(3 + c, i) = P.n[c];
    }
  }
  for (int c = 0; c < 3; ++c) {
    dd.dQ(c, i) = Q.f[c];
    dd.dQ(3 + c, i) = Q.n[c];
    dd.dG(c, i) = G.f[c];
    dd.dG(3 + c, i) = G.n[c];
    dd.dH(c, i) = H.f[c];
    dd.dH(3 + c, i) = H.n[c];
  }
  if constexpr (model::subtree_contiguous<R>(i)) {
    // Row i over the subtree (k = i, j in [i, last]).
    if constexpr (root) {
      dd.dtau_dq.row(i).template segment<L>(i) = row_dot_k<L, Scalar, K>(dd.dG, i);
      dd.dtau_dv.row(i).template segment<L>(i) = row_dot_k<L, Scalar, K>(dd.dH, i);
    } else {
      dd.dtau_dq.row(i).template segment<L>(i) = row_dot<L, Scalar>(dd.dG, i, Sc.v, Sc.w);
      dd.dtau_dv.row(i).template segment<L>(i) = row_dot<L, Scalar>(dd.dH, i, Sc.v, Sc.w);
    }
    if constexpr (WithM) {
      Eigen::Matrix<Scalar, 1, L> mrow;
      if constexpr (root)
        mrow = row_dot_k<L, Scalar, K>(dd.dP, i);
      else
        mrow = row_dot<L, Scalar>(dd.dP, i, Sc.v, Sc.w);
      d.M.row(i).template segment<L>(i) = mrow;
      d.M.col(i).template segment<L>(i) = mrow.transpose();
    }
    // Column i below the diagonal over the strict subtree (j = i ancestor of k in (i, last]).
    if constexpr (L > 1) {
      const Motion<Scalar>& ddS = dd.ddS[i];
      if constexpr (root) {
        dd.dtau_dq.col(i).template segment<L - 1>(i + 1) =
            row_dot3<L - 1, Scalar>(dd.dP, i + 1, ddS.v).transpose();
        dd.dtau_dv.col(i).template segment<L - 1>(i + 1) =
            row_dot_k<L - 1, Scalar, K>(dd.dQ, i + 1).transpose();
      } else {
        dd.dtau_dq.col(i).template segment<L - 1>(i + 1) =
            (row_dot<L - 1, Scalar>(dd.dP, i + 1, ddS.v, ddS.w) +
             row_dot<L - 1, Scalar>(dd.dQ, i + 1, dS.v, dS.w))
                .transpose();
        dd.dtau_dv.col(i).template segment<L - 1>(i + 1) =
            (row_dot<L - 1, Scalar>(dd.dP, i + 1, dS2.v, dS2.w) +
             row_dot<L - 1, Scalar>(dd.dQ, i + 1, Sc.v, Sc.w))
                .transpose();
      }
    }
  } else {
    // A numbering that is topological but not depth-first: the range [i, last] also holds
    // bodies of other branches, so each member of the subtree is taken on its own.
    static_for<L>([&](auto J) {
      constexpr int j = i + decltype(J)::value;
      if constexpr (!model::support<R>[j][i]) {
        dd.dtau_dq(i, j) = Scalar(0);
        dd.dtau_dq(j, i) = Scalar(0);
        dd.dtau_dv(i, j) = Scalar(0);
        dd.dtau_dv(j, i) = Scalar(0);
        if constexpr (WithM) {
          d.M(i, j) = Scalar(0);
          d.M(j, i) = Scalar(0);
        }
      } else {
        dd.dtau_dq(i, j) = row_dot<1, Scalar>(dd.dG, j, Sc.v, Sc.w)[0];
        dd.dtau_dv(i, j) = row_dot<1, Scalar>(dd.dH, j, Sc.v, Sc.w)[0];
        if constexpr (WithM) {
          const Scalar m = row_dot<1, Scalar>(dd.dP, j, Sc.v, Sc.w)[0];
          d.M(i, j) = m;
          d.M(j, i) = m;
        }
        if constexpr (j > i) {
          const Motion<Scalar>& ddS = dd.ddS[i];
          dd.dtau_dq(j, i) = row_dot<1, Scalar>(dd.dP, j, ddS.v, ddS.w)[0] +
                             row_dot<1, Scalar>(dd.dQ, j, dS.v, dS.w)[0];
          dd.dtau_dv(j, i) = Scalar(2) * row_dot<1, Scalar>(dd.dP, j, dS.v, dS.w)[0] +
                             row_dot<1, Scalar>(dd.dQ, j, Sc.v, Sc.w)[0];
        }
      }
    });
  }
  // Pairs on different branches: zero (rows and columns past the subtree).
  if constexpr (last + 1 < n) {
    dd.dtau_dq.row(i).template tail<n - last - 1>().setZero();
    dd.dtau_dq.col(i).template tail<n - last - 1>().setZero();
    dd.dtau_dv.row(i).template tail<n - last - 1>().setZero();
    dd.dtau_dv.col(i).template tail<n - last - 1>().setZero();
    if constexpr (WithM) {
      d.M.row(i).template tail<n - last - 1>().setZero();
      d.M.col(i).template tail<n - last - 1>().setZero();
    }
  }
  if constexpr (B::parent >= 0) {
    constexpr int p = B::parent;
    if constexpr (!Fused)
      sx::add_to(dd.oYcrb[p], Y);
    sx::add_to(dd.oYdot[p], Yd);
    sx::add_to(dd.oh[p], h);
    sx::add_to(dd.of[p], F);
  }
}

/// The whole derivative sweep at (q, v, a): data.tau, dtau_dq, dtau_dv and, WithM, data.M.
template <class R, bool WithM, bool HasFext, class Scalar, class Q, class V, class A>
ARBOR_INLINE void rnea_derivatives_impl(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd,
                                        const Eigen::MatrixBase<Q>& q,
                                        const Eigen::MatrixBase<V>& v,
                                        const Eigen::MatrixBase<A>& a, const Vec3<Scalar>& g,
                                        const typename Data<R, Scalar>::ForceArray* fext) {
  constexpr bool flat = std::is_floating_point_v<Scalar>;  // per-body passes flattened
  joint_states(d, q);
  static_for_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    deriv_forward_velocity<R, i, HasFext>(d, dd, v, fext);
    deriv_forward_acceleration<R, i>(d, dd, v, a, g);
  });
  if (d.payload.active)
    deriv_forward_payload(d, dd);
  static_for_reverse_flat<R::nb, flat>(
      [&](auto I) { deriv_backward_body<R, decltype(I)::value, WithM>(d, dd); });
}

}  // namespace detail

/// Derivatives of inverse dynamics tau = ID(q, v, a) with gravity g (world frame):
/// deriv.dtau_dq = d tau / d q, deriv.dtau_dv = d tau / d v, data.M = d tau / d a (full
/// symmetric) and data.tau = ID(q, v, a). Also leaves data.oMi, data.J (world joint columns) and
/// the world-frame velocities deriv.ov and accelerations deriv.oa. O(n d); no allocation.
template <Robot R, class Scalar, class Q, class V, class A>
void rnea_derivatives(Data<R, Scalar>& data, DerivativeData<R, Scalar>& deriv,
                      const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                      const Eigen::MatrixBase<A>& a,
                      const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  detail::check_sizes<R, Q, V, A>();
  detail::rnea_derivatives_impl<R, true, false>(data, deriv, q, v, a, g, nullptr);
}

/// rnea_derivatives with external forces fext (one per body, body frame, held fixed in the body
/// frames).
template <Robot R, class Scalar, class Q, class V, class A>
void rnea_derivatives(Data<R, Scalar>& data, DerivativeData<R, Scalar>& deriv,
                      const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                      const Eigen::MatrixBase<A>& a, const Vec3<Scalar>& g,
                      const ForceArray<R, Scalar>& fext) {
  detail::check_sizes<R, Q, V, A>();
  detail::rnea_derivatives_impl<R, true, true>(data, deriv, q, v, a, g, &fext);
}

}  // namespace arbor
