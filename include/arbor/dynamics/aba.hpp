// arbor: articulated-body algorithm (forward dynamics ddq = FD(q, v, tau)).
#pragma once

#include "arbor/core/static_for.hpp"
#include "arbor/dynamics/data.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/payload.hpp"
#include "arbor/dynamics/rnea.hpp"
#include "arbor/spatial/sx.hpp"

namespace arbor {

namespace detail {

/// The child of body p that comes last in the tree's numbering (the first one the backward
/// passes visit), -1 for a leaf.
template <class R>
constexpr int last_child(int p) {
  int c = -1;
  for (int j = 0; j < R::nb; ++j)
    if (R::parent[j] == p)
      c = j;
  return c;
}

/// Body i's step of the leaves-to-root articulated-inertia passes (aba's pass 2, minverse's
/// backward pass) starts here: Yaba[i] complete (a leaf's own inertia, else its children have
/// added theirs; WithPayload: the payload's inertia added on its body), U[i] = Yaba[i] S and
/// Dinv[i] = 1 / (S' U[i]) stored; returns Dinv[i].
template <class R, int i, bool WithPayload, class Scalar>
ARBOR_INLINE Scalar art_body_start(Data<R, Scalar>& d) {
  using B = spatial::BodyOps<R, i, Scalar>;
  if constexpr (last_child<R>(i) < 0)
    d.Yaba[i] = B::art_inertia();  // a leaf (else set by its last child)
  if constexpr (WithPayload) {
    if (i == d.payload.body)
      add_payload_art(d.Yaba[i], d.payload.Y);
  }
  B::art_S(d.Yaba[i], d.U[i]);
  const Scalar Dinv = Scalar(1) / B::ST(d.U[i]);
  d.Dinv[i] = Dinv;
  return Dinv;
}

/// The ABA's second pass: articulated inertias and bias forces, leaves to root. WithPayload: the
/// payload's inertia added to its body's articulated inertia.
template <class R, bool WithPayload, class Scalar, class T>
ARBOR_INLINE void aba_pass2(Data<R, Scalar>& d, const Eigen::MatrixBase<T>& tau) {
  constexpr bool flat = std::is_floating_point_v<Scalar>;  // per-body passes flattened
  static_for_reverse_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    const Scalar Dinv = art_body_start<R, i, WithPayload>(d);
    const Scalar ui = Scalar(tau[i]) - B::ST(d.pA[i]);
    d.u[i] = ui;
    if constexpr (B::parent >= 0) {
      // pa = pA + Ya c + U Dinv u with Ya = Y - U Dinv U^T: Ya c = Y c - U Dinv (U . c)
      const Motion<Scalar>& c = d.a[i];
      Force<Scalar> pa = spatial::art_times<B::cross_S_nz>(d.Yaba[i], c);
      const Scalar g = Dinv * (ui - spatial::dot_masked<B::cross_S_nz>(d.U[i], c));
      for (int r = 0; r < 3; ++r) {
        pa.f[r] += d.pA[i].f[r] + d.U[i].f[r] * g;
        pa.n[r] += d.pA[i].n[r] + d.U[i].n[r] * g;
      }
      using BP = spatial::BodyOps<R, B::parent, Scalar>;
      using Init = std::conditional_t<last_child<R>(B::parent) == i, BP, void>;
      B::template add_art_projection<Init>(d.joint[i], d.Yaba[i], d.U[i], Dinv, d.Yaba[B::parent]);
      B::add_force_to_parent(d.joint[i], pa, d.pA[B::parent]);
    }
  });
}

/// The payload's bias force v x* Yp v added to its body's (aba's pass 1), out of line.
template <class R, class Scalar>
ARBOR_NOINLINE void aba_payload_bias(Data<R, Scalar>& d) {
  const int b = d.payload.body;
  d.pA[b] += spatial::cross(d.v[b], d.payload.Y * d.v[b]);
}

/// aba_pass2 with the payload, out of line (called only when one is set).
template <class R, class Scalar, class T>
ARBOR_NOINLINE void aba_pass2_payload(Data<R, Scalar>& d, const Eigen::MatrixBase<T>& tau) {
  aba_pass2<R, true>(d, tau);
}

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
    Motion<Scalar> vel;
    if constexpr (B::parent < 0) {
      vel = B::S_times(vi);
      d.a[i] = Motion<Scalar>::Zero();  // v_parent = 0, so c = v x S v = 0
    } else {
      vel = B::motion_to_child(js, d.v[B::parent]);
      B::add_S(vel, vi);
      Motion<Scalar> c = Motion<Scalar>::Zero();
      B::add_cross_S(c, vel, vi);
      d.a[i] = c;
    }
    d.v[i] = vel;
    if constexpr (B::massless)
      d.pA[i] = Force<Scalar>::Zero();
    else
      d.pA[i] = sx::fcross(vel, B::inertia_times(vel));
    if (fext)  // a run-time test: if constexpr here costs 1-4 % more (GCC 12 inlining)
      d.pA[i] -= (*fext)[i];
  });
  // A payload: its bias force v x* Yp v on its body (out of line).
  if (d.payload.active)
    aba_payload_bias(d);
  // Pass 2: articulated inertias and bias forces, leaves to root; with a payload, its second
  // instantiation (aba_pass2), out of line: the plain path keeps the inlining budget it had
  // without the feature.
  if (d.payload.active)
    aba_pass2_payload<R>(d, tau);
  else
    aba_pass2<R, false>(d, tau);
  // Pass 3: accelerations, root to leaves (the base accelerates by -g).
  static_for_flat<R::nb, flat>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, Scalar>;
    Motion<Scalar> ai;
    Scalar ddq;
    if constexpr (B::parent < 0) {
      ai.v = B::linear_to_child(d.joint[i], -g);
      ai.w.setZero();
      ddq = d.Dinv[i] * (d.u[i] - spatial::dot_masked<0x7u>(d.U[i], ai));
    } else {
      ai = B::motion_to_child(d.joint[i], d.a[B::parent]);
      const Motion<Scalar>& c = d.a[i];
      static_for<3>([&](auto J) {
        constexpr int j = decltype(J)::value;
        if constexpr ((B::cross_S_nz >> j) & 1u)
          ai.v[j] += c.v[j];
        if constexpr ((B::cross_S_nz >> (3 + j)) & 1u)
          ai.w[j] += c.w[j];
      });
      ddq = d.Dinv[i] * (d.u[i] - sx::dot(d.U[i], ai));
    }
    d.ddq[i] = ddq;
    B::add_S(ai, ddq);
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
