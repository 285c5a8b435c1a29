// arbor: the entry points: evaluate, and the derivatives by forward mode over the same nodes:
// jacobian/gradient/value_and_jacobian evaluate at S = Dual<T, n> with the differentiated
// arguments seeded (n = their total size, a compile-time constant); hessian and
// value_gradient_hessian evaluate at S = Dual<Dual<T, n>, n> (forward over forward; both
// triangles are computed, the result is symmetric to rounding). T is the arguments' scalar.
//
// Argument i is the value of Symbol<i, N> (an Eigen fixed-size column vector of N rows, or a
// plain scalar when N == 1). Derivatives are taken with respect to all arguments stacked in Id
// order, or with respect to the listed Ids only, in the listed order (`jacobian<0>(e, x, u)` is
// d e / d x; the other arguments are parameters). Cost: one evaluation of the tree at S; stack
// use grows with sizeof(S) = sizeof(T) (n + 1) (Hessians: (n + 1)^2).
#pragma once

#include <Eigen/Core>
#include <array>
#include <type_traits>
#include <utility>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/expr/environment.hpp"
#include "arbor/ad/expr/values.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::ad {

/// Value and Jacobian of a vector expression (one evaluation).
template <class T, int M, int N>
struct ValueJacobian {
  VecN<T, M> value;                 ///< e(args)
  Eigen::Matrix<T, M, N> jacobian;  ///< d e / d (differentiated args)
};

/// Value, gradient and Hessian of a scalar expression (one evaluation).
template <class T, int N>
struct ValueGradientHessian {
  T value;              ///< e(args)
  VecN<T, N> gradient;  ///< d e / d (differentiated args)
  MatN<T, N> hessian;   ///< d^2 e / d (differentiated args)^2 (symmetric to rounding)
};

namespace detail {
template <int... Wrt>
struct IdList {};

/// Where each argument's derivative directions start (-1: not differentiated) and how many.
template <class Ids, class... A>
struct Layout;
template <int... Wrt, class... A>
struct Layout<IdList<Wrt...>, A...> {
  static_assert(wrt_valid<sizeof...(A), Wrt...>(),
                "the Ids to differentiate with respect to must be distinct argument indices");
  static constexpr std::array<int, sizeof...(A)> offsets =
      wrt_offsets<sizeof...(A), Wrt...>(ArgPack<std::remove_cvref_t<A>...>::sizes);
  static constexpr int directions = wrt_size(ArgPack<std::remove_cvref_t<A>...>::sizes, offsets);
};

/// e evaluated at S with the arguments seeded as listed in Wrt.
template <class S, int... Wrt, Expression E, class... A>
Values<S, E::rows> eval_at(const E& e, const A&... args) {
  using T = scalar_of_args<A...>;
  constexpr auto off = Layout<IdList<Wrt...>, A...>::offsets;
  const auto env =
      make_env<S, T, !std::is_same_v<S, T>, off>(std::index_sequence_for<A...>{}, args...);
  return e.eval(env);
}

/// The environment of a first-derivative evaluation: the arguments at Dual<T, n> seeded as listed
/// in Wrt (n their total size). Several expressions of the same arguments evaluated in one
/// environment (value_and_jacobian_in) seed the arguments once.
template <int... Wrt, class... A>
auto jacobian_env(const A&... args) {
  using T = scalar_of_args<A...>;
  constexpr int n = Layout<IdList<Wrt...>, A...>::directions;
  static_assert(n >= 1, "nothing to differentiate with respect to");
  constexpr auto off = Layout<IdList<Wrt...>, A...>::offsets;
  return make_env<Dual<T, n>, T, true, off>(std::index_sequence_for<A...>{}, args...);
}

/// Value and Jacobian of e in an environment made by jacobian_env.
template <class Env, Expression E>
auto value_and_jacobian_in(const Env& env, const E& e) {
  using S = typename Env::Scalar;
  using T = typename S::Value;
  constexpr int n = S::directions;
  const Values<S, E::rows> r = e.eval(env);
  ValueJacobian<T, E::rows, n> out;
  for (int i = 0; i < E::rows; ++i) {
    out.value[i] = r[i].v;
    for (int k = 0; k < n; ++k)
      out.jacobian(i, k) = r[i].d[k];
  }
  return out;
}
}  // namespace detail

/// Value of e; argument i is the value of Symbol<i, N> (Eigen N-vector, or a scalar if N == 1).
template <Expression E, class... A>
VecN<detail::scalar_of_args<A...>, E::rows> evaluate(const E& e, const A&... args) {
  return detail::to_eigen(detail::eval_at<detail::scalar_of_args<A...>>(e, args...));
}

/// Value and Jacobian of e with respect to the arguments Wrt... (all, stacked by Id, if none).
template <int... Wrt, Expression E, class... A>
auto value_and_jacobian(const E& e, const A&... args) {
  return detail::value_and_jacobian_in(detail::jacobian_env<Wrt...>(args...), e);
}

/// Jacobian of e with respect to the arguments Wrt... (all, stacked by Id, if none).
template <int... Wrt, Expression E, class... A>
auto jacobian(const E& e, const A&... args) {
  return value_and_jacobian<Wrt...>(e, args...).jacobian;
}

/// Gradient of a scalar expression (1 row) with respect to Wrt... (all if none).
template <int... Wrt, Expression E, class... A>
auto gradient(const E& e, const A&... args) {
  static_assert(E::rows == 1, "gradient needs a scalar (1-row) expression");
  using T = detail::scalar_of_args<A...>;
  constexpr int n = detail::Layout<detail::IdList<Wrt...>, A...>::directions;
  return VecN<T, n>(value_and_jacobian<Wrt...>(e, args...).jacobian.transpose());
}

/// Value, gradient and Hessian of a scalar expression with respect to Wrt... (all if none),
/// from one evaluation at Dual<Dual<T, n>, n>.
template <int... Wrt, Expression E, class... A>
auto value_gradient_hessian(const E& e, const A&... args) {
  static_assert(E::rows == 1, "hessian needs a scalar (1-row) expression");
  using T = detail::scalar_of_args<A...>;
  constexpr int n = detail::Layout<detail::IdList<Wrt...>, A...>::directions;
  static_assert(n >= 1, "nothing to differentiate with respect to");
  using S = Dual<Dual<T, n>, n>;
  const Values<S, 1> r = detail::eval_at<S, Wrt...>(e, args...);
  ValueGradientHessian<T, n> out;
  out.value = r[0].v.v;
  for (int a = 0; a < n; ++a) {
    out.gradient[a] = r[0].v.d[a];
    for (int b = 0; b < n; ++b)
      out.hessian(a, b) = r[0].d[a].d[b];
  }
  return out;
}

/// Hessian of a scalar expression with respect to Wrt... (all if none).
template <int... Wrt, Expression E, class... A>
auto hessian(const E& e, const A&... args) {
  return value_gradient_hessian<Wrt...>(e, args...).hessian;
}

}  // namespace arbor::ad
