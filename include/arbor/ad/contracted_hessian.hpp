// arbor: second order of the RBD function objects: H = d^2 (lambda^T F(x)) / dx^2, the Hessian of
// F's outputs weighted by lambda (F's second-derivative tensor contracted with lambda: the term an
// exact-Hessian SQP adds for a constraint or dynamics F with multipliers lambda).
//   AutoDiff     forward over forward: nested Dual<Dual<T, nin>, chunk> through F's templates,
//                the outer directions in chunks of at most 8 (the paper's H^c);
//   Analytical   Dual<T, nin> through the analytical first-order routine (the paper's H^a);
//   Generated    straight-line code generated at build time (gen/ad: one symbolic reverse sweep
//                for the gradient of lambda^T F, then its Jacobian, forward or reverse; the
//                robot's generated <robots/NAME_ad_hessian.hpp> must be included);
//   SecondOrder  the analytical second-order routines at T (rnea_second_order_derivatives,
//                aba_second_order_derivatives; InverseDynamics and ForwardDynamics only).
// Cost: AutoDiff ~ (nin / chunk) passes at nested duals; Analytical one derivative sweep at
// Dual<T, nin>; SecondOrder one O(n d) sweep at T (FD: plus aba_derivatives and 3 n^3
// multiply-adds). HessianWorkspace<F, Tag, T> names the workspace each needs.
#pragma once

#include <type_traits>

#include "arbor/ad/rbd_functions.hpp"
#include "arbor/derivatives/aba_second_order.hpp"
#include "arbor/derivatives/rnea_second_order.hpp"
#include "arbor/derivatives/second_order_data.hpp"

namespace arbor::ad {

namespace detail {
/// Outer chunk of the forward-over-forward Hessian: at most 8 directions per pass (a 21 x 21
/// nested dual would exceed Eigen's fixed-size limit in the 7 x 7 matrices of Data; chunks of 7
/// cost 9% more than one pass).
template <int n>
inline constexpr int hessian_chunk = (n + (n + 7) / 8 - 1) / ((n + 7) / 8);
}  // namespace detail

/// The workspace of contracted_hessian<SecondOrder> for robot R at scalar T: a Data and a
/// DerivativeData at T (so value and value_and_jacobian work on it too) and a SecondOrderData.
template <class R, class T>
struct SecondOrderWorkspace : RbdWorkspace<R, Scalars<T>, Scalars<T>> {
  SecondOrderData<R, T> so;  ///< the second-order sweep's arrays and results

  /// The SecondOrderData (of scalar T only).
  template <class U>
  SecondOrderData<R, U>& second_order() {
    static_assert(std::is_same_v<U, T>, "this SecondOrderWorkspace is for another scalar type");
    return so;
  }
};

/// The workspace contracted_hessian<Tag> of F needs at scalar T.
template <class F, class Tag, class T = double>
using HessianWorkspace = std::conditional_t<
    std::is_same_v<Tag, Generated>, RbdWorkspace<typename F::Robot, Scalars<>>,
    std::conditional_t<
        std::is_same_v<Tag, SecondOrder>, SecondOrderWorkspace<typename F::Robot, T>,
        std::conditional_t<
            std::is_same_v<Tag, Analytical>,
            RbdWorkspace<
                typename F::Robot, Scalars<Dual<T, F::nin>>,
                std::conditional_t<F::needs_derivative_data, Scalars<Dual<T, F::nin>>, Scalars<>>>,
            RbdWorkspace<typename F::Robot,
                         Scalars<Dual<Dual<T, F::nin>, detail::hessian_chunk<F::nin>>>>>>>;

/// H = d^2 (lambda^T F(x)) / dx^2 (symmetric, nin x nin) from provider Tag, for the function of
/// handle f (bind<F>(ws) with ws a HessianWorkspace<F, Tag, T>); also returns y = F(x).
template <class Tag, class F, class W, class T>
void contracted_hessian(const Bound<F, W>& f, const VecN<T, F::nin>& x,
                        const VecN<T, F::nout>& lambda, VecN<T, F::nout>& y,
                        Eigen::Matrix<T, F::nin, F::nin>& H) {
  if constexpr (std::is_same_v<Tag, Generated>) {
    static_assert(GeneratedHessian<F>::available,
                  "no generated Hessian for this function: generate the robot's AD code with "
                  "HESSIANS (CMake arbor_add_robot_ad) and include <robots/NAME_ad_hessian.hpp> "
                  "before this call");
    // a payload set on a SecondOrderWorkspace: the generated code knows only the robot's
    // constant inertias, so the analytical second-order routines answer
    if constexpr (requires { f.ws->template second_order<T>(); }) {
      if (f.ws->template data<T>().payload.active) {
        contracted_hessian<SecondOrder>(f, x, lambda, y, H);
        return;
      }
    }
    GeneratedHessian<F>::hessian(x.data(), lambda.data(), y.data(), H.data());
  } else if constexpr (std::is_same_v<Tag, SecondOrder>) {
    using R = typename F::Robot;
    constexpr int nv = R::nv;
    constexpr bool id = std::is_same_v<F, InverseDynamics<R>>;
    static_assert(id || std::is_same_v<F, ForwardDynamics<R>>,
                  "the SecondOrder provider serves InverseDynamics and ForwardDynamics");
    auto& d = f.ws->template data<T>();
    auto& so = f.ws->template second_order<T>();
    // plain vectors: the same instantiation as a direct call with vectors
    const VecN<T, nv> q = x.template segment<nv>(0);
    const VecN<T, nv> v = x.template segment<nv>(nv);
    const VecN<T, nv> third = x.template segment<nv>(2 * nv);  // a (ID) or tau (FD)
    if constexpr (id) {
      rnea_second_order_derivatives<R>(d, so, q, v, third, lambda);
      y = d.tau;
    } else {
      aba_second_order_derivatives<R>(d, f.ws->template derivatives<T>(), so, q, v, third, lambda);
      y = d.ddq;
    }
    H = so.hessian;
  } else if constexpr (std::is_same_v<Tag, Analytical>) {
    constexpr int n = F::nin;
    constexpr int m = F::nout;
    using D = Dual<T, n>;
    VecN<D, n> xd;
    detail::seed<T, n>(x, xd);
    // d/dx_b of the analytical Jacobian, contracted with lambda.
    VecN<D, m> yd;
    Eigen::Matrix<D, m, n> Jd;
    f.template value_and_jacobian<Analytical>(xd, yd, Jd);
    for (int i = 0; i < m; ++i)
      y[i] = yd[i].v;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        T s = lambda[0] * Jd(0, a).d[b];
        for (int i = 1; i < m; ++i)
          s += lambda[i] * Jd(i, a).d[b];
        H(a, b) = s;
      }
  } else {
    static_assert(std::is_same_v<Tag, AutoDiff>,
                  "Tag must be Analytical, AutoDiff, Generated or SecondOrder");
    constexpr int n = F::nin;
    constexpr int m = F::nout;
    using D = Dual<T, n>;
    VecN<D, n> xd;
    detail::seed<T, n>(x, xd);
    constexpr int chunk = detail::hessian_chunk<n>;
    using DD = Dual<D, chunk>;
    for (int c0 = 0; c0 < n; c0 += chunk) {
      VecN<DD, n> xdd;
      for (int k = 0; k < n; ++k) {
        xdd[k] = DD(xd[k]);
        if (k >= c0 && k < c0 + chunk)
          xdd[k].d[k - c0] = D(T(1));
      }
      VecN<DD, m> ydd;
      f.value(xdd, ydd);
      if (c0 == 0)
        for (int i = 0; i < m; ++i)
          y[i] = ydd[i].v.v;
      for (int a = c0; a < n && a < c0 + chunk; ++a)
        for (int b = 0; b < n; ++b) {
          T s = lambda[0] * ydd[0].d[a - c0].d[b];
          for (int i = 1; i < m; ++i)
            s += lambda[i] * ydd[i].d[a - c0].d[b];
          H(a, b) = s;
        }
    }
  }
}

}  // namespace arbor::ad
