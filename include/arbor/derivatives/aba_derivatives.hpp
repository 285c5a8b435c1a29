// arbor: first-order analytical derivatives of forward dynamics ddq = FD(q, v, tau), reusing
// M^-1 and the inverse-dynamics derivatives as Carpentier & Mansard (RSS 2018) do: at
// ddq = FD(q, v, tau), ID(q, v, ddq) = tau holds identically, so
//   d ddq / d q = -M^-1 d tau / d q,   d ddq / d v = -M^-1 d tau / d v,   d ddq / d tau = M^-1,
// with the ID derivatives evaluated at (q, v, ddq).
#pragma once

#include "arbor/derivatives/rnea_derivatives.hpp"
#include "arbor/dynamics/aba.hpp"
#include "arbor/dynamics/minverse.hpp"

namespace arbor {

/// Derivatives of forward dynamics: data.ddq = FD(q, v, tau), data.ddq_dq = d ddq / d q,
/// data.ddq_dv = d ddq / d v, data.Minv = d ddq / d tau (full symmetric). Gravity g, optional
/// external forces fext (one per body, body frame, held fixed in the body frames). Also leaves
/// data.dtau_dq and data.dtau_dv at (q, v, ddq). O(n d) sweeps plus two n x n products.
template <Robot R, class S, class Q, class V, class T>
void aba_derivatives(Data<R, S>& d, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                     const Eigen::MatrixBase<T>& tau, const Vec3<S>& g = default_gravity<S>(),
                     const typename Data<R, S>::ForceArray* fext = nullptr) {
  static_assert(Q::RowsAtCompileTime == R::nq && V::RowsAtCompileTime == R::nv &&
                    T::RowsAtCompileTime == R::nv,
                "q, v, tau have the wrong size");
  aba<R>(d, q, v, tau, g, fext);
  minverse<R>(d, q);
  if (fext)
    detail::rnea_derivatives_impl<R, false, true>(d, q, v, d.ddq, g, fext);
  else
    detail::rnea_derivatives_impl<R, false, false>(d, q, v, d.ddq, g, fext);
  d.ddq_dq.noalias() = -d.Minv * d.dtau_dq;
  d.ddq_dv.noalias() = -d.Minv * d.dtau_dv;
}

/// aba_derivatives with external forces (one per body, body frame) and gravity g.
template <Robot R, class S, class Q, class V, class T>
void aba_derivatives(Data<R, S>& d, const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v,
                     const Eigen::MatrixBase<T>& tau, const Vec3<S>& g,
                     const typename Data<R, S>::ForceArray& fext) {
  aba_derivatives<R>(d, q, v, tau, g, &fext);
}

}  // namespace arbor
