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
//
// Sensitivities. `rk4<M>` (Sensitivity::exact) differentiates the RK4 map exactly: f's Jacobian
// at all 4 M stage states. `rk4<M, Sensitivity::frozen>` computes the same map (its values agree
// with exact's to rounding) but freezes f's Jacobian at the interval's start: f and its Jacobian
// J0 = [A0 B0] are evaluated there once, every other stage evaluates f's value only (at the plain
// scalar: an RBD call runs its value routine, e.g. aba instead of aba_derivatives) and takes
// d k = B0 + A0 d x_stage (A0 read in place from the first stage's derivatives). The
// result is the exact derivative of RK4 applied to f's linearisation at the start (x, u): it
// differs from the exact one by O(h^2) (A's change over the interval, times h), which an SQP or
// RTI sees as an inexact Jacobian of the dynamics constraint (its residual stays exact: a loop
// converges to a feasible trajectory; optimality is perturbed by O(h^2) |lambda|). Cost per
// interval: one evaluation of f at S and 4 M - 1 at the plain scalar, plus per stage one product
// A0 d x_stage over A0's nonzero entries at the point (nnz(A0) n multiply-adds). Frozen applies to
// first-derivative evaluations whose state argument is seeded (the OCP's linearisation); a value
// evaluation, a Hessian (two dual levels) or an unseeded state take the exact path.
#pragma once

#include <cstddef>
#include <tuple>
#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/expr/scalar.hpp"
#include "arbor/ad/expr/structure.hpp"
#include "arbor/ad/expr/values.hpp"
#include "arbor/core/math.hpp"

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
  static constexpr int arguments = Parent::arguments;              ///< as the parent's
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

/// Plain values (no derivatives) of the arguments of Parent other than the state, for the frozen
/// scheme's value-only stage evaluations; made once per evaluation of the RK4 node.
template <class Parent, class B, int I = 1>
auto argument_values(const Parent& parent) {
  if constexpr (I >= Parent::arguments) {
    return std::tuple<>{};
  } else {
    const auto& a = parent.template arg<I>();
    using A = std::remove_cvref_t<decltype(a)>;
    ad::Values<B, A::size> v;
    for (int j = 0; j < A::size; ++j)
      v[j] = a[j].v;
    return std::tuple_cat(std::make_tuple(v), argument_values<Parent, B, I + 1>(parent));
  }
}

/// The environment of a frozen stage's value evaluation: plain scalar B, the state `x`, the other
/// arguments' values from `rest` (argument_values); nothing seeded.
template <class B, class V, class Rest>
struct ValueEnv {
  using Scalar = B;                                                   ///< the plain scalar
  static constexpr bool seeded = false;                               ///< nothing is differentiated
  static constexpr int levels = 0;                                    ///< no dual level
  static constexpr int arguments = 1 + int(std::tuple_size_v<Rest>);  ///< state + the others
  const V& x;                                                         ///< the stage state's values
  const Rest& rest;  ///< the other arguments' values
  /// Not differentiated.
  template <int Id>
  static constexpr int offset() {
    return -1;
  }
  /// Not differentiated.
  template <int Id>
  static constexpr bool unit_seeds() {
    return false;
  }
  /// Argument Id's values.
  template <int Id>
  const auto& arg() const {
    if constexpr (Id == 0)
      return x;
    else
      return std::get<std::size_t(Id - 1)>(rest);
  }
  /// A let bound outside the RK4 node: not available in a frozen stage.
  template <class K>
  void bound() const {
    static_assert(ad::detail::always_false<K>,
                  "rk4<M, Sensitivity::frozen>: f may not use a let placeholder bound outside "
                  "the rk4 node (bind it inside f, or use Sensitivity::exact)");
  }
};
}  // namespace detail

/// How an RK4 node differentiates (see the top of this file).
enum class Sensitivity {
  exact,   ///< f's Jacobian at every stage state: the exact derivative of the RK4 map
  frozen,  ///< f's Jacobian at the interval's start only; the other stages' values only
};

/// Expression node: M explicit RK4 steps of f over an interval h (see the top of this file).
template <int M, ad::Expression F, Sensitivity Sens = Sensitivity::exact>
struct Rk4Expr {
  static_assert(M >= 1, "rk4<M>: M >= 1 steps");
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = F::rows;  ///< state size (f returns xdot)
  F f;                                  ///< the ODE right-hand side
  double h;                             ///< interval length
  /// True when evaluation in Env takes the frozen scheme.
  template <class Env>
  static constexpr bool frozen_in() {
    if constexpr (Sens == Sensitivity::frozen && ad::detail::env_levels<Env>() == 1 &&
                  ad::is_dual_v<typename Env::Scalar>)
      return Env::template unit_seeds<0>() && Env::template offset<0>() >= 0;
    else
      return false;
  }

  /// x after M steps.
  template <class Env>
  ad::Values<typename Env::Scalar, rows> eval(const Env& env) const {
    if constexpr (frozen_in<Env>())
      return eval_frozen(env);
    else
      return eval_exact(env);
  }

  /// x after M steps, f's Jacobian at every stage.
  template <class Env>
  ad::Values<typename Env::Scalar, rows> eval_exact(const Env& env) const {
    using V = ad::Values<typename Env::Scalar, rows>;
    static_assert(std::remove_cvref_t<decltype(env.template arg<0>())>::size == rows,
                  "rk4: the state argument (Symbol<0, n>) must have f's size");
    // k1 of the first step is f at the argument itself: the parent environment (whose state may
    // carry unit seeds, which call nodes scatter instead of multiplying); the other stages with
    // the stage state substituted
    return steps(env.template arg<0>(), V(f.eval(env)), [&](const V& xs) {
      return V(f.eval(detail::StateEnv<Env, V>{env, xs}));
    });
  }

  /// x after M steps, f's Jacobian at the interval's start only (Sensitivity::frozen).
  template <class Env>
  ad::Values<typename Env::Scalar, rows> eval_frozen(const Env& env) const {
    using S = typename Env::Scalar;
    using B = typename S::Value;
    using V = ad::Values<S, rows>;
    using Vb = ad::Values<B, rows>;
    constexpr int n = rows;
    constexpr int K = S::directions;
    constexpr int o0 = Env::template offset<0>();
    static_assert(o0 + n <= K, "rk4: the state's directions lie outside the evaluation's");
    static_assert(std::remove_cvref_t<decltype(env.template arg<0>())>::size == n,
                  "rk4: the state argument (Symbol<0, n>) must have f's size");
    // f and its Jacobian at the start: k1 = f(x) (exact); A0 = d f / d x is k1's state columns
    // (the state's seeds are unit vectors from o0), read in place
    const V k1 = f.eval(env);
    const auto rest = detail::argument_values<Env, B>(env);
    using Rest = std::remove_const_t<decltype(rest)>;
    // any other stage: the value of f at the stage state; the derivative k1.d + A0 (d x_stage -
    // E), E the state's seeds, over A0's nonzero entries (k1.d alone is f's derivative at the
    // start)
    return steps(env.template arg<0>(), k1, [&](const V& xs) {
      Vb xv;
      for (int i = 0; i < n; ++i)
        xv[i] = xs[i].v;
      const auto& kv = f.eval(detail::ValueEnv<B, Vb, Rest>{xv, rest});
      V k = k1;
      for (int i = 0; i < n; ++i) {
        k[i].v = kv[i];
        for (int j = 0; j < n; ++j) {
          const B a = k1[i].d[o0 + j];
          if (!known_zero(a)) {  // (a tracing scalar: structural zeros only)
            for (int d = 0; d < K; ++d)
              k[i].d[d] += a * xs[j].d[d];
            k[i].d[o0 + j] -= a;
          }
        }
      }
      return k;
    });
  }

 private:
  /// M RK4 steps from x0: k1 is the first step's first stage, stage(xs) f at any other stage
  /// state (the exact or the frozen scheme). (x is a local, not a by-value parameter, so that
  /// the result is built in place: a parameter cannot be.)
  template <class S, class Stage>
  ad::Values<S, rows> steps(const ad::Values<S, rows>& x0, const ad::Values<S, rows>& k1,
                            const Stage& stage) const {
    using B = ad::detail::base_t<S>;
    using V = ad::Values<S, rows>;
    constexpr int n = rows;
    V x = x0;
    const B dt = B(h / M), half = B(h / (2 * M)), sixth = B(h / (6 * M));
    V xs, acc;
    // one step from the stage value ka at x: the stage states and the weighted sum k1 + 2 k2 +
    // 2 k3 are updated in place (no temporary duals: on a target without SIMD their zeroing and
    // copying cost more than the arithmetic); the operations and their order are those of
    // x + (k1 + 2 k2 + 2 k3 + k4) h/6
    auto step = [&](const V& ka) {
      using ad::detail::add_scaled_to;
      for (int i = 0; i < n; ++i)
        add_scaled_to(xs[i], x[i], ka[i], half);
      const V k2 = stage(xs);
      for (int i = 0; i < n; ++i) {
        add_scaled_to(xs[i], x[i], k2[i], half);
        add_scaled_to(acc[i], ka[i], k2[i], B(2));
      }
      const V k3 = stage(xs);
      for (int i = 0; i < n; ++i) {
        add_scaled_to(xs[i], x[i], k3[i], dt);
        add_scaled_to(acc[i], acc[i], k3[i], B(2));
      }
      const V k4 = stage(xs);
      for (int i = 0; i < n; ++i)
        ad::detail::add_sum_scaled_to(x[i], x[i], acc[i], k4[i], sixth);
    };
    step(k1);
    for (int m = 1; m < M; ++m)
      step(stage(x));
    return x;
  }
};

/// F(x, u, p): M RK4 steps of xdot = f(x, u, p) over an interval h; Sens = Sensitivity::frozen
/// for f's Jacobian at the interval's start only (see the top of this file).
template <int M, Sensitivity Sens = Sensitivity::exact, ad::Expression F>
Rk4Expr<M, F, Sens> rk4(const F& f, double h) {
  return {f, h};
}

}  // namespace arbor::ocp
