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
//   G_j = S_j x* F_j + Y_j ddS_j + Yd_j dS_j + dS_j x* h_j,   H_j = 2 Y_j dS_j + Yd_j S_j + S_j x*
//   h_j,
// for k an ancestor of j or j itself, and for j a strict ancestor of k:
//   d tau_k / d q_j = S_k . G_j,      d tau_j / d q_k = P_j . ddS_k + Q_j . dS_k,
//   d tau_k / d v_j = S_k . H_j,      d tau_j / d v_k = 2 P_j . dS_k + Q_j . S_k,
//   M_kj = S_k . P_j,
// and zero for pairs of joints on different branches. Per joint the cost is constant; the pair
// sums run over each joint's subtree, whose columns are contiguous (depth-first numbering), as
// row-vector operations across those columns: O(n d) for a tree of depth d.
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/derivatives/derivative_data.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/jacobian.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/minverse.hpp"
#include "arbor/dynamics/rnea.hpp"

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
  const Motion<Scalar> Sc = world_column<R, i, Scalar>(d);
  d.J.col(i) << Sc.v, Sc.w;
  const Scalar vi = Scalar(v[i]);
  if constexpr (B::parent < 0) {
    dd.dS[i] = Motion<Scalar>::Zero();
    dd.ov[i] = Sc * vi;
  } else {
    const Motion<Scalar>& vp = dd.ov[B::parent];
    dd.dS[i] = cross_col<B>(vp, Sc);
    dd.ov[i] = vp + Sc * vi;
  }
  if constexpr (W::massless) {
    dd.oYcrb[i] = Inertia<Scalar>::Zero();
    dd.oYdot[i] = spatial::InertiaRate<Scalar>::Zero();
    dd.oh[i] = Force<Scalar>::Zero();
    dd.of[i] = Force<Scalar>::Zero();
  } else {
    dd.oYcrb[i] = W::of(d.oMi[i]);
    dd.oh[i] = dd.oYcrb[i] * dd.ov[i];
    dd.of[i] = spatial::cross(dd.ov[i], dd.oh[i]);
    dd.oYdot[i] = W::rate(dd.oYcrb[i], dd.ov[i]);
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
  const Motion<Scalar> Sc = Motion<Scalar>::from(d.J.col(i));
  const Scalar ai = Scalar(a[i]);
  if constexpr (B::parent < 0) {
    // v_p = 0, a_p = (-g, 0): ddS = (-g) x S = [-g x S.w; 0]
    if constexpr (B::revolute)
      dd.ddS[i] = {Sc.w.cross(g), Vec3<Scalar>::Zero()};
    else
      dd.ddS[i] = Motion<Scalar>::Zero();
    dd.oa[i] = {Sc.v * ai - g, Sc.w * ai};
  } else {
    constexpr int p = B::parent;
    const Motion<Scalar>& ap = dd.oa[p];
    dd.ddS[i] = cross_col<B>(ap, Sc) + spatial::cross(dd.ov[p], dd.dS[i]);
    dd.oa[i] = ap + dd.dS[i] * Scalar(v[i]) + Sc * ai;
  }
  if constexpr (!WorldInertia<R, i, Scalar>::massless)
    dd.of[i] += dd.oYcrb[i] * dd.oa[i];
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
  const Motion<Scalar> Sc = Motion<Scalar>::from(d.J.col(i));
  const Motion<Scalar>& dS = dd.dS[i];
  const Inertia<Scalar>& Y = Fused ? d.Ycrb[i] : dd.oYcrb[i];
  const spatial::InertiaRate<Scalar>& Yd = dd.oYdot[i];
  const Force<Scalar>& h = dd.oh[i];
  const Force<Scalar>& F = dd.of[i];

  d.tau[i] = spatial::dot(F, Sc);
  const Force<Scalar> YdS = Yd * Sc;
  const Force<Scalar> Sxh = cross_col_force<B>(Sc, h);
  const Force<Scalar> Q = YdS - Sxh;
  const Force<Scalar> G =
      cross_col_force<B>(Sc, F) + Y * dd.ddS[i] + Yd * dS + spatial::cross(dS, h);
  const Force<Scalar> H = Y * dS * Scalar(2) + YdS + Sxh;
  if constexpr (!Fused) {
    const Force<Scalar> P = Y * Sc;
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
    dd.dtau_dq.row(i).template segment<L>(i) = row_dot<L, Scalar>(dd.dG, i, Sc.v, Sc.w);
    dd.dtau_dv.row(i).template segment<L>(i) = row_dot<L, Scalar>(dd.dH, i, Sc.v, Sc.w);
    if constexpr (WithM) {
      const auto mrow = row_dot<L, Scalar>(dd.dP, i, Sc.v, Sc.w);
      d.M.row(i).template segment<L>(i) = mrow;
      d.M.col(i).template segment<L>(i) = mrow.transpose();
    }
    // Column i below the diagonal over the strict subtree (j = i ancestor of k in (i, last]).
    if constexpr (L > 1) {
      const Motion<Scalar>& ddS = dd.ddS[i];
      dd.dtau_dq.col(i).template segment<L - 1>(i + 1) =
          (row_dot<L - 1, Scalar>(dd.dP, i + 1, ddS.v, ddS.w) +
           row_dot<L - 1, Scalar>(dd.dQ, i + 1, dS.v, dS.w))
              .transpose();
      const Vec3<Scalar> dSv2 = dS.v * Scalar(2), dSw2 = dS.w * Scalar(2);
      dd.dtau_dv.col(i).template segment<L - 1>(i + 1) =
          (row_dot<L - 1, Scalar>(dd.dP, i + 1, dSv2, dSw2) +
           row_dot<L - 1, Scalar>(dd.dQ, i + 1, Sc.v, Sc.w))
              .transpose();
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
      dd.oYcrb[p] += Y;
    dd.oYdot[p] += Yd;
    dd.oh[p] += h;
    dd.of[p] += F;
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
