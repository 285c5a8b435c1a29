// arbor::ocp: a continuous ODE xdot = f(x, u, p) made a discrete map x+ = F(x, u, p) by explicit
// Runge-Kutta 4 with M steps of length h / M over a shooting interval h:
//   auto F = ocp::rk4<M>(f, h);   // f an expression in x = Symbol<0, nx>, u, p; F one too
// F is an expression node: it is differentiated (first and second order) by the expression layer
// like any other, and an RBD call inside f keeps its derivative provider (call<Analytical> ...).
// No `let` pyramid to write: the node evaluates f at the four stage states of each step by
// substituting the state argument (the other arguments, u and p, are shared).
// Cost: 4 M evaluations of f plus 10 M nx scalar operations; at S = Dual<T, n> every evaluation of
// f is one at S; the stage updates are in place. The first evaluation runs in the caller's
// environment (the state is the argument itself: a call node in f scatters the Jacobian columns of
// seeded arguments instead of multiplying), the others with the stage state substituted (call nodes
// multiply only the state's columns: the input and parameter columns are still seeds). Stack: 6 nx
// values of S.
#pragma once

#include "arbor/ad/expr/scalar.hpp"
#include "arbor/ad/expr/structure.hpp"
#include "arbor/ad/expr/values.hpp"

namespace arbor::ocp {

namespace detail {
/// An environment equal to Parent except that argument 0 (the state) is `x`. Derivatives of x are
/// general (not unit seeds), so the environment is not `seeded` (call nodes apply the chain rule
/// to it); the other arguments keep the parent's seeds (call nodes scatter their columns).
template <class Parent, class V>
struct StateEnv {
  using Scalar = typename Parent::Scalar;  ///< scalar type of the evaluation
  static constexpr bool seeded = false;    ///< argument 0 is not a seeded argument
  static constexpr int levels = ad::detail::env_levels<Parent>();  ///< the parent's dual levels
  const Parent& parent;                                            ///< enclosing environment
  const V& x;                                                      ///< the substituted state
  /// First derivative direction of argument Id (as the parent's).
  template <int Id>
  static constexpr int offset() {
    return Parent::template offset<Id>();
  }
  /// Argument Id's derivatives are its seeds: not the substituted state's, the parent's others.
  template <int Id>
  static constexpr bool unit_seeds() {
    if constexpr (Id == 0)
      return false;
    else
      return Parent::template unit_seeds<Id>();
  }
  /// Argument Id: the substituted state for Id 0, the parent's otherwise.
  template <int Id>
  const auto& arg() const {
    if constexpr (Id == 0)
      return x;
    else
      return parent.template arg<Id>();
  }
  /// Value bound by an enclosing let.
  template <class K>
  const auto& bound() const {
    return parent.template bound<K>();
  }
};
}  // namespace detail

/// Expression node: M explicit RK4 steps of f over an interval h (see the top of this file).
template <int M, ad::Expression F>
struct Rk4Expr {
  static_assert(M >= 1, "rk4<M>: M >= 1 steps");
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = F::rows;  ///< state size (f returns xdot)
  F f;                                  ///< the ODE right-hand side
  double h;                             ///< interval length
  /// x after M steps.
  template <class Env>
  ad::Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using S = typename Env::Scalar;
    using B = ad::detail::base_t<S>;
    using V = ad::Values<S, rows>;
    constexpr int n = rows;
    const B dt = B(h / M), half = B(h / (2 * M)), sixth = B(h / (6 * M));
    V x = env.template arg<0>();
    static_assert(V::size == n, "rk4: the state argument (Symbol<0, n>) must have f's size");
    V xs, acc;
    for (int m = 0; m < M; ++m) {
      // k1 of the first step is f at the argument itself: the parent environment (whose state
      // may carry unit seeds, which call nodes scatter instead of multiplying)
      const V k1 = m == 0 ? V(f.eval(env)) : V(f.eval(detail::StateEnv<Env, V>{env, x}));
      // the stage states and the weighted sum k1 + 2 k2 + 2 k3 are updated in place (no
      // temporary duals: on a target without SIMD their zeroing and copying cost more than the
      // arithmetic); the operations and their order are those of x + (k1 + 2 k2 + 2 k3 + k4) h/6
      using ad::detail::add_scaled_to;
      for (int i = 0; i < n; ++i)
        add_scaled_to(xs[i], x[i], k1[i], half);
      const V k2 = f.eval(detail::StateEnv<Env, V>{env, xs});
      for (int i = 0; i < n; ++i) {
        add_scaled_to(xs[i], x[i], k2[i], half);
        add_scaled_to(acc[i], k1[i], k2[i], B(2));
      }
      const V k3 = f.eval(detail::StateEnv<Env, V>{env, xs});
      for (int i = 0; i < n; ++i) {
        add_scaled_to(xs[i], x[i], k3[i], dt);
        add_scaled_to(acc[i], acc[i], k3[i], B(2));
      }
      const V k4 = f.eval(detail::StateEnv<Env, V>{env, xs});
      for (int i = 0; i < n; ++i)
        ad::detail::add_sum_scaled_to(x[i], x[i], acc[i], k4[i], sixth);
    }
    return x;
  }
};

/// F(x, u, p): M RK4 steps of xdot = f(x, u, p) over an interval h.
template <int M, ad::Expression F>
Rk4Expr<M, F> rk4(const F& f, double h) {
  return {f, h};
}

}  // namespace arbor::ocp
