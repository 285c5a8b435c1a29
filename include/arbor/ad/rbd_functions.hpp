// arbor: RBD functions as differentiable function objects, with a choice of Jacobian provider.
//
// Each function object F is a stateless type with
//   static constexpr int nin, nout;
//   template <class T> static void value(const VecN<T, nin>& x, VecN<T, nout>& y);
//   template <class Tag, class T>
//   static void value_and_jacobian(const VecN<T, nin>& x, VecN<T, nout>& y,
//                                  Eigen::Matrix<T, nout, nin>& J);
// (the last from detail::JacobianProviders, given `template <class T> analytical(x, y, J)`).
// The provider tag chooses where J comes from:
//   Analytical  the analytical derivative routines (rnea_derivatives, aba_derivatives,
//               frame_position_derivative): the paper's J^a;
//   AutoDiff    Dual<T, nin> through the RBD templates: the paper's J^c.
// Both providers return the primal value from the same pass (shared work).
//
// The functions are:
//   ForwardDynamics<R>      x = (q, v, tau) -> ddq         (aba)
//   InverseDynamics<R>      x = (q, v, a)   -> tau         (rnea)
//   FramePosition<R, F>     x = q           -> p_F (world) (forward kinematics)
//
// Second order: hessian<Tag, F>(x, lambda, H) gives H = d^2 (lambda^T F(x)) / dx^2:
//   AutoDiff    nested Dual<Dual<T, nin>, nin> through the RBD templates (the paper's H^c);
//   Analytical  Dual<T, nin> through the analytical first-order routine (the paper's H^a).
//
// Workspaces: one static Data<R, S> per robot and scalar type (detail::workspace), so the calls
// never allocate and need no caller-side storage, but they are not reentrant: do not call the
// same function object with the same scalar type from two threads or interrupt levels at once.
// The dual workspaces are large (Data<R, Dual<Dual<double, 21>, 7>> is about 3 MB for a 7-DoF
// arm); they exist only in programs that instantiate them. For big robots, Data<R, Dual<T, N>>
// can exceed Eigen's fixed-size object limit (EIGEN_STACK_ALLOCATION_LIMIT, 128 KB: a static
// assertion); the objects are static here, so define EIGEN_STACK_ALLOCATION_LIMIT=0 for such
// programs (the tests and benchmarks do for Atlas).
#pragma once

#include <Eigen/Core>

#include "arbor/ad/dual.hpp"
#include "arbor/derivatives/aba_derivatives.hpp"
#include "arbor/derivatives/frame_derivatives.hpp"
#include "arbor/derivatives/rnea_derivatives.hpp"
#include "arbor/dynamics/aba.hpp"
#include "arbor/dynamics/jacobian.hpp"
#include "arbor/dynamics/kinematics.hpp"
#include "arbor/dynamics/rnea.hpp"

namespace arbor::ad {

/// Jacobian provider tag: the analytical derivative routines (J^a; H^a for second order).
struct Analytical {};
/// Jacobian provider tag: Dual numbers through the RBD templates (J^c; H^c for second order).
struct AutoDiff {};

namespace detail {
/// The static workspace of robot R at scalar S (zero-initialised at program start).
template <class R, class S>
inline Data<R, S> workspace{};

template <class T, int N, class X>
void seed(const Eigen::MatrixBase<X>& x, VecN<Dual<T, N>, N>& xd) {
  for (int k = 0; k < N; ++k)
    xd[k] = Dual<T, N>::variable(x[k], k);
}
template <class T, int N, int M>
void unseed(const VecN<Dual<T, N>, M>& yd, VecN<T, M>& y, Eigen::Matrix<T, M, N>& J) {
  for (int i = 0; i < M; ++i) {
    y[i] = yd[i].v;
    for (int k = 0; k < N; ++k)
      J(i, k) = yd[i].d[k];
  }
}
/// J^c: one pass of Dual<T, F::nin> through F::value, seeded with the unit directions.
template <class F, class T>
void autodiff_jacobian(const VecN<T, F::nin>& x, VecN<T, F::nout>& y,
                       Eigen::Matrix<T, F::nout, F::nin>& J) {
  using D = Dual<T, F::nin>;
  VecN<D, F::nin> xd;
  seed<T, F::nin>(x, xd);
  VecN<D, F::nout> yd;
  F::template value<D>(xd, yd);
  unseed<T, F::nin, F::nout>(yd, y, J);
}

/// value_and_jacobian<Tag, T> of a function object F with static value<T> and analytical<T>
/// (value and J^a from one pass): the one place where the provider tag is dispatched.
template <class F>
struct JacobianProviders {
  /// y = F(x) and J = d y / d x from the provider Tag (Analytical: F::analytical; AutoDiff:
  /// autodiff_jacobian). G only defers the sizes until F is complete.
  template <class Tag, class T, class G = F>
  static void value_and_jacobian(const VecN<T, G::nin>& x, VecN<T, G::nout>& y,
                                 Eigen::Matrix<T, G::nout, G::nin>& J) {
    if constexpr (std::is_same_v<Tag, Analytical>) {
      G::analytical(x, y, J);
    } else {
      static_assert(std::is_same_v<Tag, AutoDiff>, "Tag must be Analytical or AutoDiff");
      autodiff_jacobian<G>(x, y, J);
    }
  }
};
}  // namespace detail

/// Forward dynamics x = (q, v, tau) -> ddq of robot R.
template <Robot R>
struct ForwardDynamics : detail::JacobianProviders<ForwardDynamics<R>> {
  static constexpr int nv = R::nv;    ///< DoF
  static constexpr int nin = 3 * nv;  ///< inputs (q, v, tau)
  static constexpr int nout = nv;     ///< outputs (ddq)

  /// y = aba(q, v, tau).
  template <class T>
  static void value(const VecN<T, nin>& x, VecN<T, nout>& y) {
    auto& d = detail::workspace<R, T>;
    aba<R>(d, x.template segment<nv>(0), x.template segment<nv>(nv),
           x.template segment<nv>(2 * nv));
    y = d.ddq;
  }

  /// y = aba(q, v, tau) and J^a = d y / d x from the analytical routine, in one pass.
  template <class T>
  static void analytical(const VecN<T, nin>& x, VecN<T, nout>& y, Eigen::Matrix<T, nout, nin>& J) {
    auto& d = detail::workspace<R, T>;
    aba_derivatives<R>(d, x.template segment<nv>(0), x.template segment<nv>(nv),
                       x.template segment<nv>(2 * nv));
    y = d.ddq;
    J.template leftCols<nv>() = d.ddq_dq;
    J.template middleCols<nv>(nv) = d.ddq_dv;
    J.template rightCols<nv>() = d.Minv;
  }
};

/// Inverse dynamics x = (q, v, a) -> tau of robot R.
template <Robot R>
struct InverseDynamics : detail::JacobianProviders<InverseDynamics<R>> {
  static constexpr int nv = R::nv;    ///< DoF
  static constexpr int nin = 3 * nv;  ///< inputs (q, v, a)
  static constexpr int nout = nv;     ///< outputs (tau)

  /// y = rnea(q, v, a).
  template <class T>
  static void value(const VecN<T, nin>& x, VecN<T, nout>& y) {
    auto& d = detail::workspace<R, T>;
    rnea<R>(d, x.template segment<nv>(0), x.template segment<nv>(nv),
            x.template segment<nv>(2 * nv));
    y = d.tau;
  }

  /// y = rnea(q, v, a) and J^a = d y / d x from the analytical routine, in one pass.
  template <class T>
  static void analytical(const VecN<T, nin>& x, VecN<T, nout>& y, Eigen::Matrix<T, nout, nin>& J) {
    auto& d = detail::workspace<R, T>;
    rnea_derivatives<R>(d, x.template segment<nv>(0), x.template segment<nv>(nv),
                        x.template segment<nv>(2 * nv));
    y = d.tau;
    J.template leftCols<nv>() = d.dtau_dq;
    J.template middleCols<nv>(nv) = d.dtau_dv;
    J.template rightCols<nv>() = d.M;
  }
};

/// World position of operational frame F of robot R: x = q -> p (3).
template <Robot R, int F>
struct FramePosition : detail::JacobianProviders<FramePosition<R, F>> {
  static_assert(F >= 0 && F < R::nf, "frame index out of range");
  static constexpr int nin = R::nv;  ///< inputs (q)
  static constexpr int nout = 3;     ///< outputs (position)

  /// y = position of frame F at q.
  template <class T>
  static void value(const VecN<T, nin>& x, VecN<T, nout>& y) {
    auto& d = detail::workspace<R, T>;
    forward_kinematics<R>(d, x);
    y = frame_placement<R>(d, F).p;
  }

  /// y and J^a = d y / d q from compute_frame_position_derivative, in one pass.
  template <class T>
  static void analytical(const VecN<T, nin>& x, VecN<T, nout>& y, Eigen::Matrix<T, nout, nin>& J) {
    auto& d = detail::workspace<R, T>;
    compute_frame_position_derivative<R>(d, x, F, J);
    y = d.oMf[F].p;
  }
};

/// Jacobian of F at x from provider Tag (also returns the value y).
template <class Tag, class F, class T>
void jacobian(const VecN<T, F::nin>& x, VecN<T, F::nout>& y, Eigen::Matrix<T, F::nout, F::nin>& J) {
  F::template value_and_jacobian<Tag, T>(x, y, J);
}

/// Hessian H = d^2 (lambda^T F(x)) / dx^2 (symmetric, nin x nin) from provider Tag:
/// AutoDiff is H^c (nested duals through F's templates), Analytical is H^a (duals through the
/// analytical Jacobian routine). Also returns the value y = F(x).
template <class Tag, class F, class T>
void hessian(const VecN<T, F::nin>& x, const VecN<T, F::nout>& lambda, VecN<T, F::nout>& y,
             Eigen::Matrix<T, F::nin, F::nin>& H) {
  constexpr int n = F::nin;
  constexpr int m = F::nout;
  using D = Dual<T, n>;
  VecN<D, n> xd;
  detail::seed<T, n>(x, xd);
  if constexpr (std::is_same_v<Tag, Analytical>) {
    // d/dx_b of the analytical Jacobian, contracted with lambda.
    VecN<D, m> yd;
    Eigen::Matrix<D, m, n> Jd;
    F::template value_and_jacobian<Analytical, D>(xd, yd, Jd);
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
    static_assert(std::is_same_v<Tag, AutoDiff>, "Tag must be Analytical or AutoDiff");
    // Forward over forward, the outer directions in chunks of at most 8 (a 21 x 21 nested dual
    // would exceed Eigen's fixed-size limit in the 7 x 7 matrices of Data; chunks of 7 cost 9%
    // more than one pass).
    constexpr int passes = (n + 7) / 8;
    constexpr int chunk = (n + passes - 1) / passes;
    using DD = Dual<D, chunk>;
    for (int c0 = 0; c0 < n; c0 += chunk) {
      VecN<DD, n> xdd;
      for (int k = 0; k < n; ++k) {
        xdd[k] = DD(xd[k]);
        if (k >= c0 && k < c0 + chunk)
          xdd[k].d[k - c0] = D(T(1));
      }
      VecN<DD, m> ydd;
      F::template value<DD>(xdd, ydd);
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
