// arbor::ocp: the outer convex functions of convex-over-nonlinear terms, phi(r) in a cost
// phi(r(x, u, p)) and psi(c) in a constraint psi(c(x, u, p)) <= 0, and the expression node that
// applies one to an inner expression (used for exact Hessians).
//
// An outer function Phi of an M-vector provides, for any scalar T (double, float, duals):
//   T          value(const VecN<T, M>& r)      phi(r), generic code (it is differentiated by the
//                                              expression layer for exact-Hessian SQP)
//   VecN<T, M> gradient(const VecN<T, M>& r)   grad phi(r)
//   MatN<T, M> hessian(const VecN<T, M>& r)    grad^2 phi(r), positive semidefinite
// SCQP's Hessian uses only the last two (J' grad^2 phi J: no second derivative of r). An outer
// function whose Hessian is diagonal may also provide
//   VecN<T, M> hessian_diagonal(const VecN<T, M>& r)   the diagonal of grad^2 phi(r)
// (DiagonalHessian below); the Gauss-Newton product J' grad^2 phi J is then a sum of rank-one
// updates over the structurally nonzero entries of each row of J (ocp/linearize.hpp) instead of
// a dense triple product. Provided:
//   WeightedSquares<M>  sum_i w_i r_i^2, w_i >= 0    (least squares; "weights multiply squares")
//   Ball<M>             |r|^2 - rho^2                (a tunnel |e| <= rho, as psi <= 0)
// Cost: O(M) per value or gradient, O(M^2) per Hessian.
#pragma once

#include <Eigen/Core>
#include <array>
#include <concepts>
#include <cstddef>

#include "arbor/ad/expr/values.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::ocp {

/// An outer convex function of M-vectors (see the top of this file).
template <class Phi, int M>
concept OuterFunction = requires(const Phi& phi, const VecN<double, M>& r) {
  { phi.template value<double, M>(r) } -> std::convertible_to<double>;
  { phi.template gradient<double, M>(r) } -> std::convertible_to<VecN<double, M>>;
  { phi.template hessian<double, M>(r) } -> std::convertible_to<MatN<double, M>>;
};

/// Outer functions with a diagonal Hessian: hessian_diagonal(r) is the diagonal of hessian(r),
/// which is zero elsewhere.
template <class Phi, class T, int M>
concept DiagonalHessian = requires(const Phi& phi, const VecN<T, M>& r) {
  { phi.template hessian_diagonal<T, M>(r) } -> std::convertible_to<VecN<T, M>>;
};

/// sum_i w_i r_i^2 with w_i >= 0.
template <int M>
struct WeightedSquares {
  std::array<double, std::size_t(M)> w;  ///< weights (>= 0)
  /// sum_i w_i r_i^2.
  template <class T, int K>
  T value(const VecN<T, K>& r) const {
    T s = T(w[0]) * r[0] * r[0];
    for (int i = 1; i < K; ++i)
      s += T(w[std::size_t(i)]) * r[i] * r[i];
    return s;
  }
  /// 2 w_i r_i.
  template <class T, int K>
  VecN<T, K> gradient(const VecN<T, K>& r) const {
    VecN<T, K> g;
    for (int i = 0; i < K; ++i)
      g[i] = T(2 * w[std::size_t(i)]) * r[i];
    return g;
  }
  /// diag(2 w).
  template <class T, int K>
  MatN<T, K> hessian(const VecN<T, K>&) const {
    MatN<T, K> h = MatN<T, K>::Zero();
    for (int i = 0; i < K; ++i)
      h(i, i) = T(2 * w[std::size_t(i)]);
    return h;
  }
  /// 2 w (the diagonal of the Hessian).
  template <class T, int K>
  VecN<T, K> hessian_diagonal(const VecN<T, K>&) const {
    VecN<T, K> h;
    for (int i = 0; i < K; ++i)
      h[i] = T(2 * w[std::size_t(i)]);
    return h;
  }
};

/// |r|^2 - rho^2: psi(c) <= 0 keeps c in the ball of radius rho.
template <int M>
struct Ball {
  double rho;  ///< radius (> 0)
  /// |r|^2 - rho^2.
  template <class T, int K>
  T value(const VecN<T, K>& r) const {
    T s = r[0] * r[0];
    for (int i = 1; i < K; ++i)
      s += r[i] * r[i];
    return s - T(rho * rho);
  }
  /// 2 r.
  template <class T, int K>
  VecN<T, K> gradient(const VecN<T, K>& r) const {
    return T(2) * r;
  }
  /// 2 I.
  template <class T, int K>
  MatN<T, K> hessian(const VecN<T, K>&) const {
    return T(2) * MatN<T, K>::Identity();
  }
  /// 2 (the diagonal of the Hessian).
  template <class T, int K>
  VecN<T, K> hessian_diagonal(const VecN<T, K>&) const {
    return VecN<T, K>::Constant(T(2));
  }
};

/// Expression node phi(inner): one row (used to differentiate a convex-over-nonlinear term
/// twice; the solvers' Gauss-Newton Hessians do not need it).
template <class Phi, ad::Expression E>
struct OuterExpr {
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = 1;  ///< size
  Phi phi;                        ///< outer function
  E inner;                        ///< inner expression r
  /// phi(r) at the environment's scalar.
  template <class Env>
  ad::Values<typename Env::Scalar, 1> eval(const Env& env) const {
    using S = typename Env::Scalar;
    const auto& r = inner.eval(env);
    VecN<S, E::rows> rv;
    for (int i = 0; i < E::rows; ++i)
      rv[i] = r[i];
    ad::Values<S, 1> out;
    out[0] = phi.template value<S, E::rows>(rv);
    return out;
  }
};

}  // namespace arbor::ocp
