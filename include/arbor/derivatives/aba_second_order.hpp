// arbor: contracted second-order derivatives of forward dynamics: the Hessian of
// lambda' FD(q, v, tau) with respect to x = (q, v, tau), from inverse dynamics' second-order
// derivatives and M^-1 through the identity ID(q, v, FD(q, v, tau)) = tau (Singh, Russell &
// Wensing 2022 use the same identity). With u = (q, v), ddq = FD(x), A = d ddq / d u and
// mu = M^-1 lambda, differentiating mu' ID(u, ddq(x)) = mu' tau twice gives
//   H_FD = -Z' H_ID(mu) Z,   Z = d(u, ddq)/dx = [1 0; A M^-1],
// and since the a-a and a-v blocks of H_ID vanish, with Hqa = d2(mu' ID)/dq da:
//   H_FD = -[Hqq + Hqa A_q + (Hqa A_q)'   Hqv + Hqa A_v   Hqa M^-1]
//           [  (Hqv + Hqa A_v)'            Hvv            0       ]
//           [  (Hqa M^-1)'                 0              0       ].
// Cost: aba_derivatives (one minverse, O(n d) sweeps, two n x n products), the O(n d) ID
// second-order sweep at (q, v, ddq) reusing its placements, and 3 n^3 multiply-adds (fewer for
// trees where under 60% of the joint pairs are on one branch: the zeros off the branches are
// skipped).
#pragma once

#include "arbor/derivatives/aba_derivatives.hpp"
#include "arbor/derivatives/derivative_data.hpp"
#include "arbor/derivatives/rnea_second_order.hpp"
#include "arbor/derivatives/second_order_data.hpp"
#include "arbor/model/topology.hpp"

namespace arbor {

namespace detail {

/// True when fewer than 60% of the joint pairs lie on one branch (two arms, a humanoid): the n^3
/// products then skip the structural zeros of d2(mu' ID)/dq da and d tau/d(q, v).
template <class R>
constexpr bool so_sparse_products() {
  int on = 0;
  for (int i = 0; i < R::nv; ++i)
    for (int k = 0; k < R::nv; ++k)
      on += model::on_branch<R>[i][k] ? 1 : 0;
  return 10 * on < 6 * R::nv * R::nv;
}

/// aba_second_order_derivatives at (q, v, tau): see the file comment.
template <class R, class Scalar, class Q, class V, class T, class L>
ARBOR_INLINE void aba_second_order_impl(Data<R, Scalar>& d, DerivativeData<R, Scalar>& dd,
                                        SecondOrderData<R, Scalar>& s,
                                        const Eigen::MatrixBase<Q>& q,
                                        const Eigen::MatrixBase<V>& v,
                                        const Eigen::MatrixBase<T>& tau,
                                        const Eigen::MatrixBase<L>& lambda, const Vec3<Scalar>& g) {
  constexpr int n = R::nv;
  aba_derivatives_impl<R, false>(d, dd, q, v, tau, g, nullptr);
  const VecN<Scalar, n> lam = lambda.template cast<Scalar>();
  s.mu.noalias() = d.Minv * lam;
  // data.oMi and data.J hold the placements and world columns of q: reuse them.
  rnea_second_order_impl<R, true>(d, s, q, v, d.ddq, s.mu, g);
  auto& H = s.hessian;
  if constexpr (so_sparse_products<R>()) {
    // B = Hqa M^-1 = (M^-1 Haq)' with Haq = Hqa' zero off the branches; then C = Hqa [A_q, A_v]
    // = -B [d tau/dq, d tau/dv] (A = -M^-1 d tau/d(q, v)), whose columns are zero off the
    // branches too.
    for (int i = 0; i < n; ++i) {
      auto col = s.C.col(i);  // scratch: column i of M^-1 Haq
      col.setZero();
      for (int k = 0; k < n; ++k)
        if (model::on_branch<R>[k][i])
          col += d.Minv.col(k) * H(2 * n + k, i);
    }
    s.B = s.C.template leftCols<n>().transpose();
    for (int c = 0; c < n; ++c) {
      auto cq = s.C.col(c);
      auto cv = s.C.col(n + c);
      cq.setZero();
      cv.setZero();
      for (int k = 0; k < n; ++k)
        if (model::on_branch<R>[k][c]) {
          cq -= s.B.col(k) * dd.dtau_dq(k, c);
          cv -= s.B.col(k) * dd.dtau_dv(k, c);
        }
    }
  } else {
    const auto Hqa = H.template block<n, n>(0, 2 * n);
    s.C.template leftCols<n>().noalias() = Hqa.lazyProduct(dd.ddq_dq);
    s.C.template rightCols<n>().noalias() = Hqa.lazyProduct(dd.ddq_dv);
    s.B.noalias() = Hqa.lazyProduct(d.Minv);
  }
  // q-q, q-v, v-q, v-v
  for (int c = 0; c < n; ++c)
    for (int r = c; r < n; ++r) {
      const Scalar e = -(H(r, c) + s.C(r, c) + s.C(c, r));
      H(r, c) = e;
      H(c, r) = e;
    }
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r) {
      const Scalar e = -(H(r, n + c) + s.C(r, n + c));
      H(r, n + c) = e;
      H(n + c, r) = e;
    }
  H.template block<n, n>(n, n) = -H.template block<n, n>(n, n);
  // q-tau, tau-q (tau-tau and v-tau stay zero)
  H.template block<n, n>(0, 2 * n) = -s.B;
  H.template block<n, n>(2 * n, 0) = -s.B.transpose();
  // gradient [A_q' lambda; A_v' lambda; mu]
  s.gradient.template segment<n>(0).noalias() = dd.ddq_dq.transpose() * lam;
  s.gradient.template segment<n>(n).noalias() = dd.ddq_dv.transpose() * lam;
  s.gradient.template segment<n>(2 * n) = s.mu;
}

}  // namespace detail

/// Contracted second-order derivatives of forward dynamics ddq = FD(q, v, tau) with gravity g
/// (world frame), for multipliers lambda: so.hessian = d^2 (lambda' FD) / dx^2 with
/// x = (q, v, tau) (3n x 3n, full symmetric; the tau-tau and v-tau blocks are zero),
/// so.gradient = d (lambda' FD) / dx, data.ddq = FD(q, v, tau), and everything
/// aba_derivatives leaves (deriv.ddq_dq, deriv.ddq_dv, data.Minv). so.mu = M^-1 lambda; data.tau
/// is overwritten with ID(q, v, ddq) = tau. No allocation.
template <Robot R, class Scalar, class Q, class V, class T, class L>
void aba_second_order_derivatives(Data<R, Scalar>& data, DerivativeData<R, Scalar>& deriv,
                                  SecondOrderData<R, Scalar>& so, const Eigen::MatrixBase<Q>& q,
                                  const Eigen::MatrixBase<V>& v, const Eigen::MatrixBase<T>& tau,
                                  const Eigen::MatrixBase<L>& lambda,
                                  const Vec3<Scalar>& g = default_gravity<Scalar>()) {
  detail::check_sizes<R, Q, V, T>();
  static_assert(L::RowsAtCompileTime == R::nv && L::ColsAtCompileTime == 1,
                "lambda must be a column vector of R::nv entries");
  detail::aba_second_order_impl(data, deriv, so, q, v, tau, lambda, g);
}

}  // namespace arbor
