// arbor: articulated-body algorithm (forward dynamics ddq = FD(q, v, tau)).
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/rnea.hpp"

namespace arbor {

namespace detail {

/// The ABA's three passes, with external forces when fext is not null.
template <class R, class Scalar, class Q, class V, class T>
ARBOR_INLINE void aba_impl(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q,
                           const Eigen::MatrixBase<V>& v, const Eigen::MatrixBase<T>& tau,
                           const Vec3<Scalar>& g,
                           const typename Data<R, Scalar>::ForceArray* fext) {
  constexpr bool flat = std::is_floating_point_v<Scalar>;  // per-body passes flattened
  detail::joint_states(d, q);
  // Pass 1: velocities, velocity-product accelerations c_i (in data.a), bias forces.
  static_for_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    const JointState<Scalar>& js = d.joint[i];
    const Scalar vi = Scalar(v[i]);
    if constexpr (B::parent < 0) {
      d.v[i] = B::S_times(vi);
      d.a[i] = Motion<Scalar>::Zero();  // v_parent = 0, so c = v x S v = 0
    } else {
      d.v[i] = B::motion_to_child(js, d.v[B::parent]);
      B::add_S(d.v[i], vi);
      d.a[i] = B::cross_S(d.v[i], vi);
    }
    d.Yaba[i] = B::art_inertia();
    if constexpr (B::massless)
      d.pA[i] = Force<Scalar>::Zero();
    else
      d.pA[i] = spatial::cross(d.v[i], B::inertia_times(d.v[i]));
    if (fext)  // a run-time test: if constexpr here costs 1-4 % more (GCC 12 inlining)
      d.pA[i] -= (*fext)[i];
  });
  // Pass 2: articulated inertias and bias forces, leaves to root.
  static_for_reverse_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    B::art_S(d.Yaba[i], d.U[i].f, d.U[i].n);
    d.Dinv[i] = Scalar(1) / B::ST(d.U[i]);
    d.u[i] = Scalar(tau[i]) - B::ST(d.pA[i]);
    if constexpr (B::parent >= 0) {
      // pa = pA + Ya c + U Dinv u with Ya = Y - U Dinv U^T: Ya c = Y c - U Dinv (U . c)
      const Force<Scalar> pa = d.pA[i] + d.Yaba[i] * d.a[i] +
                               d.U[i] * (d.Dinv[i] * (d.u[i] - spatial::dot(d.U[i], d.a[i])));
      d.Yaba[B::parent] += B::art_project_to_parent(d.joint[i], d.Yaba[i], d.U[i], d.Dinv[i]);
      d.pA[B::parent] += B::force_to_parent(d.joint[i], pa);
    }
  });
  // Pass 3: accelerations, root to leaves (the base accelerates by -g).
  static_for_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    Motion<Scalar> ai;
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
}

}  // namespace detail

/// Forward dynamics ddq = FD(q, v, tau) by the ABA with gravity g (world frame). Fills data.v, a,
/// pA, Yaba, U, Dinv, u and ddq; returns data.ddq. O(n).
template <Robot R, class Scalar, class Q, class V, class T>
const typename Data<R, Scalar>::Vector& aba(Data<R, Scalar>& data, const Eigen::MatrixBase<Q>& q,
                                            const Eigen::MatrixBase<V>& v,
                                            const Eigen::MatrixBase<T>& tau,
                                            const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  detail::check_sizes<R, Q, V, T>();
  detail::aba_impl<R>(data, q, v, tau, g, nullptr);
  return data.ddq;
}

/// Forward dynamics with external forces fext (one per body, in the body frame).
template <Robot R, class Scalar, class Q, class V, class T>
const typename Data<R, Scalar>::Vector& aba(Data<R, Scalar>& data, const Eigen::MatrixBase<Q>& q,
                                            const Eigen::MatrixBase<V>& v,
                                            const Eigen::MatrixBase<T>& tau, const Vec3<Scalar>& g,
                                            const ForceArray<R, Scalar>& fext) {
  detail::check_sizes<R, Q, V, T>();
  detail::aba_impl<R>(data, q, v, tau, g, &fext);
  return data.ddq;
}

}  // namespace arbor
