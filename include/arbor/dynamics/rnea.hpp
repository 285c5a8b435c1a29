// arbor: recursive Newton-Euler inverse dynamics, generalized gravity and nonlinear effects.
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"

namespace arbor {

/// Gravity vector used when none is given [m/s^2], in the world (= fixed base) frame.
template <class S>
inline Vec3<S> default_gravity() {
  return Vec3<S>(S(0), S(0), S(-9.81));
}

namespace detail {

/// One RNEA with compile-time switches for the terms present.
template <class R, bool HasV, bool HasA, bool HasFext, class S, class Q, class V, class A>
ARBOR_INLINE void rnea_impl(Data<R, S>& d, const Eigen::MatrixBase<Q>& q,
                            const Eigen::MatrixBase<V>& v, const Eigen::MatrixBase<A>& a,
                            const Vec3<S>& g, const typename Data<R, S>::ForceArray* fext) {
  joint_states(d, q);
  // Forward pass: velocities, accelerations (the base accelerates by -g), body forces.
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, S>;
    const JointState<S>& js = d.joint[i];
    if constexpr (B::parent < 0) {
      if constexpr (HasV)
        d.v[i] = B::S_times(S(v[i]));
      d.a[i].v = B::linear_to_child(js, -g);
      d.a[i].w.setZero();
    } else {
      if constexpr (HasV) {
        d.v[i] = B::motion_to_child(js, d.v[B::parent]);
        B::add_S(d.v[i], S(v[i]));
      }
      d.a[i] = B::motion_to_child(js, d.a[B::parent]);
    }
    if constexpr (HasV)
      d.a[i] += B::cross_S(d.v[i], S(v[i]));
    if constexpr (HasA)
      B::add_S(d.a[i], S(a[i]));
    d.f[i] = B::inertia_times(d.a[i]);
    if constexpr (HasV) {
      if constexpr (!B::massless)
        d.f[i] += spatial::cross(d.v[i], B::inertia_times(d.v[i]));
    }
    if constexpr (HasFext)
      d.f[i] -= (*fext)[i];
  });
  // Backward pass: joint torques, forces to the parents.
  static_for_reverse<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, S>;
    d.tau[i] = B::ST(d.f[i]);
    if constexpr (B::parent >= 0)
      d.f[B::parent] += B::force_to_parent(d.joint[i], d.f[i]);
  });
}

}  // namespace detail

/// Inverse dynamics tau = ID(q, v, a) with gravity g (world frame) and optional external forces
/// fext (one per body, in the body frame; nullptr for none). Fills data.v, a, f, tau.
template <Robot R, class S, class Q, class V, class A>
const typename Data<R, S>::Vector& rnea(Data<R, S>& d, const Eigen::MatrixBase<Q>& q,
                                        const Eigen::MatrixBase<V>& v,
                                        const Eigen::MatrixBase<A>& a,
                                        const Vec3<S>& g = default_gravity<S>(),
                                        const typename Data<R, S>::ForceArray* fext = nullptr) {
  static_assert(Q::RowsAtCompileTime == R::nq && V::RowsAtCompileTime == R::nv &&
                    A::RowsAtCompileTime == R::nv,
                "q, v, a have the wrong size");
  if (fext)
    detail::rnea_impl<R, true, true, true>(d, q, v, a, g, fext);
  else
    detail::rnea_impl<R, true, true, false>(d, q, v, a, g, fext);
  return d.tau;
}

/// Inverse dynamics with external forces (one per body, body frame) and gravity g.
template <Robot R, class S, class Q, class V, class A>
const typename Data<R, S>::Vector& rnea(Data<R, S>& d, const Eigen::MatrixBase<Q>& q,
                                        const Eigen::MatrixBase<V>& v,
                                        const Eigen::MatrixBase<A>& a, const Vec3<S>& g,
                                        const typename Data<R, S>::ForceArray& fext) {
  detail::rnea_impl<R, true, true, true>(d, q, v, a, g, &fext);
  return d.tau;
}

/// Generalized gravity g(q) = ID(q, 0, 0).
template <Robot R, class S, class Q>
const typename Data<R, S>::Vector& gravity(Data<R, S>& d, const Eigen::MatrixBase<Q>& q,
                                           const Vec3<S>& g = default_gravity<S>()) {
  detail::rnea_impl<R, false, false, false>(d, q, q, q, g, nullptr);
  return d.tau;
}

/// Nonlinear effects C(q, v) v + g(q) = ID(q, v, 0).
template <Robot R, class S, class Q, class V>
const typename Data<R, S>::Vector& nle(Data<R, S>& d, const Eigen::MatrixBase<Q>& q,
                                       const Eigen::MatrixBase<V>& v,
                                       const Vec3<S>& g = default_gravity<S>()) {
  detail::rnea_impl<R, true, false, false>(d, q, v, v, g, nullptr);
  return d.tau;
}

}  // namespace arbor
