// arbor: materialisation boundaries, for subexpressions used more than once. A node that appears
// twice in a tree is evaluated twice, and a subexpression used k times inside a stage that is
// itself used k times is evaluated k^depth times (e.g. a naive RK4 step built from expressions).
// Two boundaries evaluate something once per evaluation:
//   let(e, [](auto v) { return ... v ... v ...; })   e is evaluated once; the lambda receives a
//       placeholder bound to that value, and its result is the expression (the lambda runs once,
//       at construction; its closure type is the placeholder's key);
//   fn<Nout>([](const auto& x, const auto& u) { ... }, x_expr, u_expr)   each argument is
//       evaluated once and the generic lambda runs on the concrete vectors (VecN<S, rows>) and
//       returns an Nout-vector (or a scalar when Nout == 1). It is differentiated because it
//       runs at Dual scalars: write it as generic scalar code (use S(c) for constants mixed into
//       Eigen products, arbor::sin/cos/sqrt for functions). S is the evaluation's scalar with
//       its seeded dual levels reduced to the directions the arguments depend on
//       (structure.hpp; plain T when none); fn_dense runs the body at the evaluation's scalar.
// Cost: a let stores one value (Values<S, rows>) on the stack for its body; an fn copies its
// arguments into Eigen vectors and its result back (compressing and expanding the duals); its
// body's arithmetic scales with the directions kept, not all of them.
//
// The `auto` pitfall. `auto k1 = f(x, u);` stores an expression, not a value: every later use of
// k1 re-evaluates it. Use let or fn when a subexpression is used more than once. Inside fn
// bodies the arguments are Eigen vectors, and there `auto y = a + b;` is an Eigen expression
// holding references: do not return it when it refers to the lambda's own locals; return a VecN
// (or `.eval()`). Expressions themselves hold their children by value and never dangle.
#pragma once

#include <tuple>
#include <type_traits>

#include "arbor/ad/expr/structure.hpp"
#include "arbor/ad/expr/values.hpp"

namespace arbor::ad {

namespace detail {
/// Environment of a let body: the parent's arguments plus the value bound to Key.
template <class Key, class Parent, class V>
struct LetEnv {
  using Scalar = typename Parent::Scalar;              ///< scalar type of the evaluation
  static constexpr bool seeded = Parent::seeded;       ///< as the parent's
  static constexpr int levels = env_levels<Parent>();  ///< as the parent's
  static constexpr int arguments = Parent::arguments;  ///< as the parent's
  const Parent& parent;                                ///< enclosing environment
  V value;                                             ///< the bound value
  /// First derivative direction of argument Id (< 0: not differentiated).
  template <int Id>
  static constexpr int offset() {
    return Parent::template offset<Id>();
  }
  /// Argument Id's derivatives are its seeds (as the parent's).
  template <int Id>
  static constexpr bool unit_seeds() {
    return Parent::template unit_seeds<Id>();
  }
  /// Value of argument Id.
  template <int Id>
  const auto& arg() const {
    return parent.template arg<Id>();
  }
  /// Value bound to K (the innermost let with that key).
  template <class K>
  const auto& bound() const {
    if constexpr (std::is_same_v<K, Key>)
      return value;
    else
      return parent.template bound<K>();
  }
};
}  // namespace detail

/// Materialisation boundary: a generic function of the arguments' values, evaluated once. In a
/// derivative evaluation the body runs at a dual of only the directions its arguments depend on
/// (structure.hpp; Compressed = false: at the evaluation's scalar, for bodies that need it).
template <int Nout, bool Compress, class F, Expression... A>
struct FnExpr {
  using expression_tag = void;       ///< marks an expression node
  static constexpr int rows = Nout;  ///< size
  F f;                               ///< the body, callable with VecN<S, A::rows>...
  std::tuple<A...> args;             ///< argument expressions
  /// f(args...) at the environment's scalar, or at its compressed scalar.
  template <class Env>
  Values<typename Env::Scalar, Nout> eval(const Env& env) const {
    using S = typename Env::Scalar;
    constexpr int L = detail::env_levels<Env>();
    if constexpr (Compress && L >= 1 && is_dual_v<S>) {
      constexpr int n = S::directions;
      constexpr auto mask = detail::deps_of_all<Env, A...>();
      constexpr int K = detail::padded_directions<detail::base_t<S>, n, detail::count<n>(mask)>();
      if constexpr (K < n) {
        using C = detail::Compressed<S, K, L>;
        // static: Clang takes a local constexpr array named as a template argument in a lambda
        // for an odr-use, which the lambda would have to capture
        static constexpr auto idx = detail::kept_directions<n, K>(mask);
        static constexpr auto pos = detail::compressed_positions<n>(mask);
        const auto compress = [](const auto& v) {
          constexpr int m = std::remove_cvref_t<decltype(v)>::size;
          VecN<C, m> c;
          for (int i = 0; i < m; ++i)
            c[i] = detail::gather<L, idx, C>(v[i]);
          return c;
        };
        const Values<C, Nout> rc = std::apply(
            [&](const auto&... a) {
              return detail::to_values<C, Nout>(f(compress(a.eval(env))...));
            },
            args);
        Values<S, Nout> r;
        for (int i = 0; i < Nout; ++i)
          r[i] = detail::scatter<L, K, pos, S>(rc[i]);
        return r;
      }
    }
    return std::apply(
        [&](const auto&... a) {
          return detail::to_values<S, Nout>(f(detail::to_eigen(a.eval(env))...));
        },
        args);
  }
};

/// Placeholder for the value bound by the let with key Key (see let()).
template <class Key, int N>
struct BoundExpr {
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = N;  ///< size
  /// The bound value.
  template <class Env>
  const auto& eval(const Env& env) const {
    return env.template bound<Key>();
  }
};

/// Materialisation boundary: Sub evaluated once, its value bound for Body.
template <class Key, Expression Sub, Expression Body>
struct LetExpr {
  using expression_tag = void;             ///< marks an expression node
  static constexpr int rows = Body::rows;  ///< size
  Sub sub;                                 ///< the shared subexpression
  Body body;                               ///< the expression using it through BoundExpr<Key>
  /// body with the placeholder bound to sub's value.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using V = Values<typename Env::Scalar, Sub::rows>;
    const detail::LetEnv<Key, Env, V> inner{env, sub.eval(env)};
    return body.eval(inner);
  }
};

/// Materialisation boundary: f(values of args...) -> Nout-vector, each argument evaluated once;
/// derivatives at the compressed scalar of the directions the args depend on.
template <int Nout, class F, Expression... A>
FnExpr<Nout, true, F, A...> fn(F f, const A&... args) {
  return {f, std::tuple<A...>(args...)};
}
/// fn whose body runs at the evaluation's own scalar (every direction): for a body that needs
/// exactly that type (e.g. a workspace provided for it).
template <int Nout, class F, Expression... A>
FnExpr<Nout, false, F, A...> fn_dense(F f, const A&... args) {
  return {f, std::tuple<A...>(args...)};
}
/// Materialisation boundary: e evaluated once and bound to the placeholder passed to body.
template <Expression E, class F>
auto let(const E& e, F body) {
  using Bound = BoundExpr<F, std::remove_cvref_t<E>::rows>;
  using Body = decltype(body(Bound{}));
  static_assert(Expression<Body>, "a let body must return an expression");
  return LetExpr<F, E, Body>{e, body(Bound{})};
}

namespace detail {
/// An fn node depends on the directions of its arguments.
template <int Nout, bool Compress, class F, class... A>
struct Deps<FnExpr<Nout, Compress, F, A...>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of_all<Env, A...>();
  }
};
}  // namespace detail

/// The scalar type of a vector passed to an fn body: `using S = ScalarOf<decltype(x)>;`.
template <class X>
using ScalarOf = typename std::remove_cvref_t<X>::Scalar;

}  // namespace arbor::ad
