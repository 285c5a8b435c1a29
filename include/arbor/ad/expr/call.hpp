// arbor: custom-derivative nodes. `call<Tag>(f, args...)` applies a function object f (e.g. a
// handle of ad/rbd_functions.hpp bound to a caller-owned workspace) to the concatenation of args
// (F::nin rows) and differentiates it with the Jacobian f provides, the rest of the expression
// being differentiated by this layer (CasADi's custom_jacobian).
//
// The function object. F has `static constexpr int nin, nout` and, callable on a const f,
//   f.template value<T>(const VecN<T, nin>& x, VecN<T, nout>& y)
//   f.template value_and_jacobian<Tag, T>(const VecN<T, nin>& x, VecN<T, nout>& y,
//                                         Eigen::Matrix<T, nout, nin>& J)
// The node stores f by value, so f must be cheap to copy: a handle (a pointer to a workspace
// the caller owns and keeps alive), or an empty type; it is required to be trivially copyable.
// The workspace f refers to must provide every scalar the entry point evaluates f at, including
// the scalars f's provider runs at internally (e.g. Dual<T, nin> for AutoDiff):
//   evaluate                               f.value<T>
//   jacobian, gradient, value_and_jacobian f.value_and_jacobian<Tag, T>
//   hessian, value_gradient_hessian        f.value_and_jacobian<Tag, Dual<T, n>>
// where T is the arguments' scalar and n the number of differentiated directions of the whole
// expression. A workspace is not reentrant: two evaluations at the same time need two.
//
// Cost. At a plain scalar the node calls f.value once. At S = Dual<T, K> it calls
// f.value_and_jacobian<Tag, T> once (value and Jacobian from the same pass) and applies the
// chain rule, out.d[k] = J x.d[k] (K nout nin products). When the input is made of arguments
// directly (call<Tag>(f, q, v, tau)) their seeds are unit vectors known at compile time and the
// chain rule is a copy of J's columns (summed for an argument used twice): the node's Jacobian
// costs exactly the provider. Because T may itself be a Dual, the same node gives Hessians: with
// the RBD function objects, Tag Analytical runs the analytical first-order routine in Dual
// arithmetic (the paper's H^a), AutoDiff runs nested duals through the RBD templates (H^c).
#pragma once

#include <Eigen/Core>
#include <concepts>
#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/expr/blocks.hpp"
#include "arbor/ad/expr/leaves.hpp"
#include "arbor/ad/expr/values.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::ad {

namespace detail {
/// True for a Symbol, or a concatenation of Symbols (the argument of a call node made of
/// arguments directly).
template <class A>
inline constexpr bool is_symbol_stack_v = false;
template <int Id, int N>
inline constexpr bool is_symbol_stack_v<Symbol<Id, N>> = true;
template <class... P>
inline constexpr bool is_symbol_stack_v<CatExpr<P...>> = (is_symbol_stack_v<P> && ...);

/// out[i].d[offset(Id) + j] += J(i, col + j) for a symbol part starting at column col.
template <class Env, int Id, int N, class S, int M, class JM>
void scatter_symbol(Values<S, M>& out, const JM& J, int col) {
  constexpr int off = Env::template offset<Id>();
  if constexpr (off >= 0) {
    for (int i = 0; i < M; ++i)
      for (int j = 0; j < N; ++j)
        out[i].d[off + j] += J(i, col + j);
  }
}
template <class Env, class S, int M, class JM, int Id, int N>
void scatter_columns(Values<S, M>& out, const JM& J, Symbol<Id, N>*) {
  scatter_symbol<Env, Id, N>(out, J, 0);
}
template <class Env, class S, int M, class JM, class... P>
void scatter_columns(Values<S, M>& out, const JM& J, CatExpr<P...>*) {
  int col = 0;
  ((scatter_symbol<Env, P::id, P::rows>(out, J, col), col += P::rows), ...);
}
}  // namespace detail

/// A function object call<Tag> accepts: nin inputs, nout outputs, trivially copyable (a handle
/// or an empty type; the node keeps a copy).
template <class F>
concept CallFunction = std::is_trivially_copyable_v<F> && requires {
  { F::nin } -> std::convertible_to<int>;
  { F::nout } -> std::convertible_to<int>;
};

/// Custom-derivative node: function object f applied to an F::nin-row expression, with its
/// Jacobian from f.value_and_jacobian<Tag, T> (Tag: Analytical or AutoDiff for the RBD ones).
template <class Tag, CallFunction F, Expression A>
struct CallExpr {
  static_assert(A::rows == F::nin, "call: the arguments' total size must equal F::nin");
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = F::nout;  ///< size
  [[no_unique_address]] F f;            ///< the function object (a copy of the caller's handle)
  A arg;                                ///< the concatenated input
  /// f(x); at S = Dual<T, K>: value and Jacobian J from one provider call, d = J x.d.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using S = typename Env::Scalar;
    constexpr int nin = F::nin;
    const auto& x = arg.eval(env);
    Values<S, rows> out;
    if constexpr (is_dual_v<S>) {
      using T = typename S::Value;
      constexpr int K = S::directions;
      VecN<T, nin> xv;
      for (int j = 0; j < nin; ++j)
        xv[j] = x[j].v;
      VecN<T, rows> yv;
      Eigen::Matrix<T, rows, nin> J = Eigen::Matrix<T, rows, nin>::Zero();  // (set by f)
      f.template value_and_jacobian<Tag, T>(xv, yv, J);
      if constexpr (Env::seeded && detail::is_symbol_stack_v<A>) {
        // x is made of seeded arguments: x.d are unit vectors, so d = J x.d is a scatter of J's
        // columns (no products; parameters contribute nothing)
        for (int i = 0; i < rows; ++i)
          out[i] = S(yv[i]);
        detail::scatter_columns<Env>(out, J, static_cast<A*>(nullptr));
      } else {
        for (int i = 0; i < rows; ++i) {
          out[i].v = yv[i];
          for (int k = 0; k < K; ++k) {
            T acc = J(i, 0) * x[0].d[k];
            for (int j = 1; j < nin; ++j)
              acc += J(i, j) * x[j].d[k];
            out[i].d[k] = acc;
          }
        }
      }
    } else {
      VecN<S, rows> y;
      f.template value<S>(detail::to_eigen(x), y);
      for (int i = 0; i < rows; ++i)
        out[i] = y[i];
    }
    return out;
  }
};

/// Custom-derivative node: f (a cheap-to-copy function object, stored in the node) of the
/// concatenated args, Jacobian from provider Tag.
template <class Tag, class F, Expression... A>
auto call(const F& f, const A&... args) {
  static_assert(std::is_trivially_copyable_v<F>,
                "call<Tag>(f, ...): f is copied into the node and must be a cheap handle "
                "(trivially copyable: e.g. a pointer to a caller-owned workspace)");
  using X = decltype(cat(args...));
  return CallExpr<Tag, F, X>{f, cat(args...)};
}

}  // namespace arbor::ad
