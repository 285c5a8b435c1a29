// arbor: first-order analytical derivatives of forward dynamics ddq = FD(q, v, tau), reusing
// M^-1 and the inverse-dynamics derivatives as Carpentier & Mansard (RSS 2018) do: at
// ddq = FD(q, v, tau), ID(q, v, ddq) = tau holds identically, so
//   d ddq / d q = -M^-1 d tau / d q,   d ddq / d v = -M^-1 d tau / d v,   d ddq / d tau = M^-1,
// with the ID derivatives evaluated at (q, v, ddq). The forward dynamics themselves come out of
// the same sweep: with the velocity part of the world-frame pass done, the composite forces at
// zero joint acceleration give the nonlinear effects nle, ddq = M^-1 (tau - nle) uses the M^-1
// that the derivatives need anyway, and a forward fix-up adds the accelerations of ddq before
// the derivative pass runs (no separate aba).
#pragma once

#include <array>

#include "arbor/derivatives/rnea_derivatives.hpp"
#include "arbor/dynamics/minverse.hpp"

namespace arbor {

namespace detail {

/// on_branch<R>[k][j]: joints k and j lie on one branch (one is an ancestor of the other, or
/// k == j); d tau / d q and d tau / d v are zero elsewhere.
template <class R>
constexpr std::array<std::array<bool, R::nv>, R::nv> on_branch_table() {
  std::array<std::array<bool, R::nv>, R::nv> t{};
  for (int k = 0; k < R::nv; ++k)
    for (int j = 0; j < R::nv; ++j)
      t[k][j] = support<R>[j][k] || support<R>[k][j];
  return t;
}
template <class R>
inline constexpr auto on_branch = on_branch_table<R>();

/// data.ddq_dq = -Minv dtau_dq and data.ddq_dv = -Minv dtau_dv, skipping the structural zeros
/// of the derivative matrices (pairs of joints on different branches).
template <class R, class S>
ARBOR_INLINE void minus_minv_times_derivatives(Data<R, S>& d) {
  constexpr int n = R::nv;
  if constexpr (n < 12) {
    // small: dense coefficient-based products (fewer instructions than the skipping loop)
    d.ddq_dq.noalias() = -d.Minv.lazyProduct(d.dtau_dq);
    d.ddq_dv.noalias() = -d.Minv.lazyProduct(d.dtau_dv);
    return;
  }
  const S* Mi = d.Minv.data();  // column-major: column k at Mi + k n
  for (int j = 0; j < n; ++j) {
    S* oq = d.ddq_dq.data() + j * n;
    S* ov = d.ddq_dv.data() + j * n;
    for (int r = 0; r < n; ++r) {
      oq[r] = S(0);
      ov[r] = S(0);
    }
    for (int k = 0; k < n; ++k) {
      if (!on_branch<R>[k][j])
        continue;
      const S cq = d.dtau_dq(k, j), cv = d.dtau_dv(k, j);
      const S* mk = Mi + k * n;
      for (int r = 0; r < n; ++r) {
        oq[r] -= mk[r] * cq;
        ov[r] -= mk[r] * cv;
      }
    }
  }
}

/// aba_derivatives at (q, v, tau): see the file comment.
template <class R, bool HasFext, class S, class Q, class V, class T>
ARBOR_INLINE void aba_derivatives_impl(Data<R, S>& d, const Eigen::MatrixBase<Q>& q,
                                       const Eigen::MatrixBase<V>& v,
                                       const Eigen::MatrixBase<T>& tau, const Vec3<S>& g,
                                       const typename Data<R, S>::ForceArray* fext) {
  minverse<R>(d, q);  // also the joint states
  // Velocity part and the accelerations at ddq = 0; composite forces at ddq = 0 in data.f.
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    deriv_forward_velocity<R, i, HasFext>(d, v, fext);
    deriv_forward_acceleration<R, i>(d, v, Data<R, S>::Vector::Zero(), g);
    d.f[i] = d.of[i];
  });
  static_for_reverse<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, S>;
    d.tau[i] = spatial::dot(d.f[i], Motion<S>::from(d.J.col(i)));  // nle_i
    if constexpr (B::parent >= 0)
      d.f[B::parent] += d.f[i];
  });
  d.ddq.noalias() = d.Minv * (tau.template cast<S>() - d.tau);
  // Fix-up: world accelerations of ddq (data.a holds their increments), ddS and forces.
  static_for<R::nb>([&](auto I) {
    constexpr int i = decltype(I)::value;
    using B = spatial::BodyOps<R, i, S>;
    const Motion<S> Sc = Motion<S>::from(d.J.col(i));
    if constexpr (B::parent < 0) {
      d.a[i] = Sc * d.ddq[i];
    } else {
      const Motion<S>& dap = d.a[B::parent];
      d.a[i] = dap + Sc * d.ddq[i];
      d.ddS[i] += cross_col<B>(dap, Sc);
    }
    d.oa[i] += d.a[i];
    if constexpr (!WorldInertia<R, i, S>::massless)
      d.of[i] += d.oYcrb[i] * d.a[i];
  });
  static_for_reverse<R::nb>([&](auto I) { deriv_backward_body<R, decltype(I)::value, false>(d); });
  minus_minv_times_derivatives(d);
}

}  // namespace detail

/// Derivatives of forward dynamics: data.ddq = FD(q, v, tau), data.ddq_dq = d ddq / d q,
/// data.ddq_dv = d ddq / d v, data.Minv = d ddq / d tau (full symmetric). Gravity g, optional
/// external forces fext (one per body, body frame, held fixed in the body frames). Also leaves
/// data.dtau_dq and data.dtau_dv at (q, v, ddq), and uses data.a and data.f as scratch. O(n d)
/// sweeps, one minverse, and two n x n products.
template <Robot R, class S, class Q, class V, class T>
void aba_derivatives(Data<R, S>& d, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                     const Eigen::MatrixBase<T>& tau, const Vec3<S>& g = default_gravity<S>(),
                     const typename Data<R, S>::ForceArray* fext = nullptr) {
  static_assert(Q::RowsAtCompileTime == R::nq && V::RowsAtCompileTime == R::nv &&
                    T::RowsAtCompileTime == R::nv,
                "q, v, tau have the wrong size");
  if (fext)
    detail::aba_derivatives_impl<R, true>(d, q, v, tau, g, fext);
  else
    detail::aba_derivatives_impl<R, false>(d, q, v, tau, g, fext);
}

/// aba_derivatives with external forces (one per body, body frame) and gravity g.
template <Robot R, class S, class Q, class V, class T>
void aba_derivatives(Data<R, S>& d, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                     const Eigen::MatrixBase<T>& tau, const Vec3<S>& g,
                     const typename Data<R, S>::ForceArray& fext) {
  aba_derivatives<R>(d, q, v, tau, g, &fext);
}

}  // namespace arbor
