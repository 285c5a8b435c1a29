// arbor: custom-derivative nodes. `call<Tag>(F{}, args...)` applies an RBD function object F
// (rbd_functions.hpp: ForwardDynamics<R>, InverseDynamics<R>, FramePosition<R, Frame>) to the
// concatenation of args (F::nin rows) and differentiates it with the Jacobian F provides, the
// rest of the expression being differentiated by this layer (CasADi's custom_jacobian).
//
// Cost. At a plain scalar the node calls F::value once. At S = Dual<T, K> it calls
// F::value_and_jacobian<Tag, T> once (value and Jacobian from the same pass) and applies the
// chain rule, out.d[k] = J x.d[k] (K nout nin products). When the input is made of arguments
// directly (call<Tag>(F{}, q, v, tau)) their seeds are unit vectors known at compile time and
// the chain rule is a copy of J's columns (summed for an argument used twice): the node's
// Jacobian costs exactly the provider. Because T may itself be a Dual, the same node gives
// Hessians: Tag Analytical runs the analytical first-order routine in Dual arithmetic (the
// paper's H^a), AutoDiff runs nested duals through the RBD templates (H^c). Custom nodes use the
// static workspaces of rbd_functions.hpp (not reentrant).
#pragma once

#include <Eigen/Core>
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

/// Custom-derivative node: RBD function object F applied to an F::nin-row expression, with its
/// Jacobian from F::value_and_jacobian<Tag, T> (Tag: Analytical or AutoDiff).
template <class Tag, class F, Expression A>
struct CallExpr {
  static_assert(A::rows == F::nin, "call: the arguments' total size must equal F::nin");
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = F::nout;  ///< size
  A arg;                                ///< the concatenated input
  /// F(x); at S = Dual<T, K>: value and Jacobian J from one provider call, d = J x.d.
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
      Eigen::Matrix<T, rows, nin> J = Eigen::Matrix<T, rows, nin>::Zero();  // (set by F)
      F::template value_and_jacobian<Tag, T>(xv, yv, J);
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
      F::template value<S>(detail::to_eigen(x), y);
      for (int i = 0; i < rows; ++i)
        out[i] = y[i];
    }
    return out;
  }
};

/// Custom-derivative node: F (an rbd_functions.hpp function object) of the concatenated args,
/// Jacobian from provider Tag (Analytical or AutoDiff).
template <class Tag, class F, Expression... A>
auto call(F, const A&... args) {
  using X = decltype(cat(args...));
  return CallExpr<Tag, F, X>{cat(args...)};
}

}  // namespace arbor::ad
