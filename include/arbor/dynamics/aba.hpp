// arbor: articulated-body algorithm (forward dynamics ddq = FD(q, v, tau)).
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/rnea.hpp"

namespace arbor {

/// Forward dynamics ddq = FD(q, v, tau) by the ABA, gravity g, optional external forces (body
/// frames). Fills data.v, a, pA, Yaba, U, Dinv, u, ddq; returns data.ddq.
template <Robot R, class S, class Q, class V, class T>
const typename Data<R, S>::Vector& aba(Data<R, S>& d, const Eigen::MatrixBase<Q>& q,
                                       const Eigen::MatrixBase<V>& v,
                                       const Eigen::MatrixBase<T>& tau,
                                       const Vec3<S>& g = default_gravity<S>(),
                                       const typename Data<R, S>::ForceArray* fext = nullptr) {
  static_assert(Q::RowsAtCompileTime == R::nq && V::RowsAtCompileTime == R::nv &&
                    T::RowsAtCompileTime == R::nv,
                "q, v, tau have the wrong size");
  detail::joint_states(d, q);
  // Pass 1: velocities, velocity-product accelerations c_i (in data.a), bias forces.
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, S>;
    const JointState<S>& js = d.joint[i];
    const S vi = S(v[i]);
    if constexpr (B::parent < 0) {
      d.v[i] = B::S_times(vi);
      d.a[i] = Motion<S>::Zero();  // v_parent = 0, so c = v x S v = 0
    } else {
      d.v[i] = B::motion_to_child(js, d.v[B::parent]);
      B::add_S(d.v[i], vi);
      d.a[i] = B::cross_S(d.v[i], vi);
    }
    d.Yaba[i] = B::art_inertia();
    if constexpr (B::massless)
      d.pA[i] = Force<S>::Zero();
    else
      d.pA[i] = spatial::cross(d.v[i], B::inertia_times(d.v[i]));
    if (fext)
      d.pA[i] -= (*fext)[i];
  });
  // Pass 2: articulated inertias and bias forces, leaves to root.
  static_for_reverse<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, S>;
    B::art_S(d.Yaba[i], d.U[i].f, d.U[i].n);
    d.Dinv[i] = S(1) / B::ST(d.U[i]);
    d.u[i] = S(tau[i]) - B::ST(d.pA[i]);
    if constexpr (B::parent >= 0) {
      // pa = pA + Ya c + U Dinv u with Ya = Y - U Dinv U^T: Ya c = Y c - U Dinv (U . c)
      const Force<S> pa = d.pA[i] + d.Yaba[i] * d.a[i] +
                          d.U[i] * (d.Dinv[i] * (d.u[i] - spatial::dot(d.U[i], d.a[i])));
      d.Yaba[B::parent] += B::art_project_to_parent(d.joint[i], d.Yaba[i], d.U[i], d.Dinv[i]);
      d.pA[B::parent] += B::force_to_parent(d.joint[i], pa);
    }
  });
  // Pass 3: accelerations, root to leaves (the base accelerates by -g).
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, S>;
    Motion<S> ai;
    if constexpr (B::parent < 0) {
      ai.v = B::linear_to_child(d.joint[i], -g) + d.a[i].v;
      ai.w = d.a[i].w;
    } else {
      ai = B::motion_to_child(d.joint[i], d.a[B::parent]) + d.a[i];
    }
    d.ddq[i] = d.Dinv[i] * (d.u[i] - spatial::dot(d.U[i], ai));
    B::add_S(ai, d.ddq[i]);
    d.a[i] = ai;
  });
  return d.ddq;
}

}  // namespace arbor
