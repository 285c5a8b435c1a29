// arbor: recursive Newton-Euler inverse dynamics, generalized gravity and nonlinear effects.
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/payload.hpp"
#include "arbor/spatial/sx.hpp"

namespace arbor {

/// Gravity vector used when none is given [m/s^2], in the world (= fixed base) frame.
template <class Scalar>
inline Vec3<Scalar> default_gravity() {
  return Vec3<Scalar>(Scalar(0), Scalar(0), Scalar(-9.81));
}

namespace detail {

/// A payload's force Yp a + v x* Yp v (HasV) added to its body's, between rnea's passes; out of
/// line, so that the plain path keeps the inlining budget it had without the feature.
template <bool HasV, class R, class Scalar>
ARBOR_NOINLINE void rnea_payload(Data<R, Scalar>& d) {
  const int b = d.payload.body;
  const Inertia<Scalar>& Yp = d.payload.Y;
  d.f[b] += Yp * d.a[b];
  if constexpr (HasV)
    d.f[b] += spatial::cross(d.v[b], Yp * d.v[b]);
}

/// One RNEA with compile-time switches for the terms present.
template <class R, bool HasV, bool HasA, bool HasFext, class Scalar, class Q, class V, class A>
ARBOR_INLINE void rnea_impl(Data<R, Scalar>& d, const Eigen::MatrixBase<Q>& q,
                            const Eigen::MatrixBase<V>& v, const Eigen::MatrixBase<A>& a,
                            const Vec3<Scalar>& g,
                            const typename Data<R, Scalar>::ForceArray* fext) {
  joint_states(d, q);
  // Forward pass: velocities, accelerations (the base accelerates by -g), body forces.
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    const JointState<Scalar>& js = d.joint[i];
    Motion<Scalar> vi, ai;
    if constexpr (B::parent < 0) {
      if constexpr (HasV)
        vi = B::S_times(Scalar(v[i]));
      ai.v = B::linear_to_child(js, -g);
      ai.w.setZero();
    } else {
      if constexpr (HasV) {
        vi = B::motion_to_child(js, d.v[B::parent]);
        B::add_S(vi, Scalar(v[i]));
      }
      ai = B::motion_to_child(js, d.a[B::parent]);
    }
    if constexpr (HasV)
      B::add_cross_S(ai, vi, Scalar(v[i]));
    if constexpr (HasA)
      B::add_S(ai, Scalar(a[i]));
    Force<Scalar> fi = B::inertia_times(ai);
    if constexpr (HasV) {
      if constexpr (!B::massless)
        sx::add_to(fi, sx::fcross(vi, B::inertia_times(vi)));
      d.v[i] = vi;
    }
    if constexpr (HasFext)
      fi -= (*fext)[i];
    d.a[i] = ai;
    d.f[i] = fi;
  });
  // A payload: its force on its body (out of line, outside the unrolled passes).
  if (d.payload.active)
    rnea_payload<HasV>(d);
  // Backward pass: joint torques, forces to the parents.
  static_for_reverse<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    d.tau[i] = B::ST(d.f[i]);
    if constexpr (B::parent >= 0)
      B::add_force_to_parent(d.joint[i], d.f[i], d.f[B::parent]);
  });
}

}  // namespace detail

/// Inverse dynamics tau = ID(q, v, a) with gravity g (world frame). Fills data.v, a, f and tau;
/// returns data.tau.
template <Robot R, class Scalar, class Q, class V, class A>
const typename Data<R, Scalar>::Vector& rnea(Data<R, Scalar>& data, const Eigen::MatrixBase<Q>& q,
                                             const Eigen::MatrixBase<V>& v,
                                             const Eigen::MatrixBase<A>& a,
                                             const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  detail::check_sizes<R, Q, V, A>();
  detail::rnea_impl<R, true, true, false>(data, q, v, a, g, nullptr);
  return data.tau;
}

/// Inverse dynamics with external forces fext (one per body, in the body frame).
template <Robot R, class Scalar, class Q, class V, class A>
const typename Data<R, Scalar>::Vector& rnea(Data<R, Scalar>& data, const Eigen::MatrixBase<Q>& q,
                                             const Eigen::MatrixBase<V>& v,
                                             const Eigen::MatrixBase<A>& a, const Vec3<Scalar>& g,
                                             const ForceArray<R, Scalar>& fext) {
  detail::check_sizes<R, Q, V, A>();
  detail::rnea_impl<R, true, true, true>(data, q, v, a, g, &fext);
  return data.tau;
}

/// Generalized gravity g(q) = ID(q, 0, 0) in data.tau; returns it.
template <Robot R, class Scalar, class Q>
const typename Data<R, Scalar>::Vector& gravity(Data<R, Scalar>& data,
                                                const Eigen::MatrixBase<Q>& q,
                                                const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  static_assert(Q::RowsAtCompileTime == R::nq, "q has the wrong size");
  detail::rnea_impl<R, false, false, false>(data, q, q, q, g, nullptr);
  return data.tau;
}

/// Nonlinear effects C(q, v) v + g(q) = ID(q, v, 0) in data.tau; returns it.
template <Robot R, class Scalar, class Q, class V>
const typename Data<R, Scalar>::Vector& nle(Data<R, Scalar>& data, const Eigen::MatrixBase<Q>& q,
                                            const Eigen::MatrixBase<V>& v,
                                            const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  detail::check_sizes<R, Q, V, V>();
  detail::rnea_impl<R, true, false, false>(data, q, v, v, g, nullptr);
  return data.tau;
}

}  // namespace arbor
