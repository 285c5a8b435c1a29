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
// chain rule, out.d[k] = J x.d[k] (K nout nin products). Parts of the input that are arguments
// directly, or segments of them (call<Tag>(f, q, v, tau)), have unit seeds known at compile time:
// their share of the chain rule is a copy of J's columns (summed for an argument used twice), so
// with only such parts the node's Jacobian costs exactly the provider; the other parts (e.g. the
// substituted state of an RK4 stage, ocp/rk4.hpp) cost one product and sum per column, per
// direction those parts depend on (known at compile time, expr/structure.hpp; with SIMD, their
// contiguous range when it is at most a quarter larger, so that the loop over them vectorizes), per
// entry of J that is not identically zero (F::jacobian_nonzero() when F provides it, as generated
// user functions do: ad/user_function.hpp); at most K nout products per column. The parts of the
// input that are arguments or segments of them are read in place (no stacked copy); only the
// others are evaluated and copied. Because T may itself be a
// Dual, the same node gives Hessians: with the RBD function objects, Tag Analytical runs the
// analytical first-order routine in Dual arithmetic (the paper's H^a), AutoDiff runs nested duals
// through the RBD templates (H^c).
#pragma once

#include <Eigen/Core>
#include <array>
#include <concepts>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/expr/blocks.hpp"
#include "arbor/ad/expr/leaves.hpp"
#include "arbor/ad/expr/structure.hpp"
#include "arbor/ad/expr/values.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::ad {

namespace detail {
/// A part of a call node's input: a symbol or a segment of one (whose derivatives may be unit
/// seeds, known at compile time), or anything else (general derivatives).
template <class P>
struct CallPart {
  static constexpr int id = -1;    ///< argument Id (-1: not a symbol)
  static constexpr int start = 0;  ///< first element of the argument
};
template <int Id, int N>
struct CallPart<Symbol<Id, N>> {
  static constexpr int id = Id;
  static constexpr int start = 0;
};
template <int St, int L, int Id, int N>
struct CallPart<SegmentExpr<St, L, Symbol<Id, N>>> {
  static constexpr int id = Id;
  static constexpr int start = St;
};

/// The parts of a call node's input (a cat's operands, or the input itself).
template <class A>
struct CallParts {
  using type = std::tuple<A>;
};
template <class... P>
struct CallParts<CatExpr<P...>> {
  using type = std::tuple<P...>;
};

/// True when part P's derivatives in Env are unit seeds (a symbol, or a segment of one, of an
/// argument the environment seeds).
template <class Env, class P>
constexpr bool part_is_seeded() {
  if constexpr (CallPart<P>::id < 0)
    return false;
  else
    return unit_seeds<Env, CallPart<P>::id>();
}

/// The columns of a call node's input whose derivatives are general (parts that are not seeded
/// symbols), in order, and their number.
template <class Env, class A>
constexpr std::pair<std::array<int, std::size_t(A::rows)>, int> general_columns() {
  using Parts = typename CallParts<A>::type;
  std::array<int, std::size_t(A::rows)> cols{};
  int n = 0, col = 0;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    auto one = [&](auto part) {
      using P = typename decltype(part)::type;
      if constexpr (!part_is_seeded<Env, P>())
        for (int j = 0; j < P::rows; ++j)
          cols[std::size_t(n++)] = col + j;
      col += P::rows;
    };
    (one(std::type_identity<std::tuple_element_t<I, Parts>>{}), ...);
  }
  (std::make_index_sequence<std::tuple_size_v<Parts>>{});
  return {cols, n};
}
template <class Env, class A>
struct GeneralColumns {
  static constexpr std::array<int, std::size_t(A::rows)> cols =
      general_columns<Env, A>().first;                            ///< the columns
  static constexpr int count = general_columns<Env, A>().second;  ///< how many
};

/// The directions the general parts of a call node's input (those that are not seeded symbols)
/// depend on: the chain rule runs over these only (the others are zero for them).
template <class Env, class A>
constexpr auto general_directions() {
  using Parts = typename CallParts<A>::type;
  constexpr int n = outer_directions<typename Env::Scalar>();
  return []<std::size_t... I>(std::index_sequence<I...>) {
    DirSet<n> r{};
    auto one = [&](auto part) {
      using P = typename decltype(part)::type;
      if constexpr (!part_is_seeded<Env, P>())
        r = unite<n>(r, deps_of<Env, P>());
    };
    (one(std::type_identity<std::tuple_element_t<I, Parts>>{}), ...);
    return r;
  }
  (std::make_index_sequence<std::tuple_size_v<Parts>>{});
}

/// The entries of F's Jacobian (column major) that are not identically zero:
/// F::jacobian_nonzero() when F provides it, else all.
template <class F>
constexpr std::array<bool, std::size_t(F::nout* F::nin)> jacobian_nonzero() {
  if constexpr (requires { F::jacobian_nonzero(); }) {
    return F::jacobian_nonzero();
  } else {
    std::array<bool, std::size_t(F::nout * F::nin)> nz{};
    for (auto& b : nz)
      b = true;
    return nz;
  }
}

/// True when every part of a call node's input is a symbol or a segment of one (the input is then
/// read in place from the environment's arguments, not stacked into a copy).
template <class A>
constexpr bool all_symbol_parts() {
  return []<class... P>(std::type_identity<std::tuple<P...>>) {
    return ((CallPart<P>::id >= 0) && ...);
  }(std::type_identity<typename CallParts<A>::type>{});
}

/// The operands of a call node's input, as a tuple of references (a cat's parts, or the input).
template <class... P>
auto call_parts(const CatExpr<P...>& arg) {
  return std::apply([](const auto&... part) { return std::tie(part...); }, arg.parts);
}
template <class A>
auto call_parts(const A& arg) {
  return std::tie(arg);
}

/// px[j] = the j-th element of the input: its parts that are symbols (or segments of one) in
/// place in the environment, the others evaluated into their rows of xs (one copy of those parts
/// only; xs is unused when every part is a symbol).
template <class A, class Env, class S, class Xs>
void input_elements(const A& arg, const Env& env, Xs& xs, const S** px) {
  int col = 0;
  auto one = [&](const auto& part) {
    using Q = std::remove_cvref_t<decltype(part)>;
    if constexpr (CallPart<Q>::id >= 0) {
      const auto& a = env.template arg<CallPart<Q>::id>();
      for (int j = 0; j < Q::rows; ++j)
        px[col + j] = &a[CallPart<Q>::start + j];
    } else if constexpr (requires { xs[0]; }) {
      // (a requires-expression, not `else`: Clang checks the non-dependent xs[...] of a discarded
      // branch when the enclosing template is instantiated, and xs has no elements when every
      // part is a symbol)
      const auto& v = part.eval(env);
      for (int j = 0; j < Q::rows; ++j) {
        xs[col + j] = v[j];
        px[col + j] = &xs[col + j];
      }
    } else {
      static_assert(CallPart<Q>::id >= 0, "a part that is not a symbol needs its rows in xs");
    }
    col += Q::rows;
  };
  std::apply([&](const auto&... part) { (one(part), ...); }, call_parts(arg));
}

/// out[i].d[offset + j] += J(i, col + j) for every seeded part (its seeds are unit vectors: the
/// chain rule is a scatter of J's columns; parameters contribute nothing).
template <class Env, class A, class S, int M, class JM>
void scatter_seeded(Values<S, M>& out, const JM& J) {
  using Parts = typename CallParts<A>::type;
  int col = 0;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    auto one = [&](auto part) {
      using P = typename decltype(part)::type;
      if constexpr (part_is_seeded<Env, P>()) {
        constexpr int off = Env::template offset<CallPart<P>::id>();
        if constexpr (off >= 0) {
          for (int i = 0; i < M; ++i)
            for (int j = 0; j < P::rows; ++j)
              out[i].d[off + CallPart<P>::start + j] += J(i, col + j);
        }
      }
      col += P::rows;
    };
    (one(std::type_identity<std::tuple_element_t<I, Parts>>{}), ...);
  }
  (std::make_index_sequence<std::tuple_size_v<Parts>>{});
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
    Values<S, rows> out;
    if constexpr (is_dual_v<S>) {
      using T = typename S::Value;
      constexpr int K = S::directions;
      // the input's elements: its parts that are symbols (or segments of one) in place, the
      // others from their evaluation
      const S* px[nin];
      struct None {};
      [[maybe_unused]] std::conditional_t<detail::all_symbol_parts<A>(), None, Values<S, nin>> xs;
      detail::input_elements(arg, env, xs, px);
      VecN<T, nin> xv;
      for (int j = 0; j < nin; ++j)
        xv[j] = px[j]->v;
      VecN<T, rows> yv;
      Eigen::Matrix<T, rows, nin> J = Eigen::Matrix<T, rows, nin>::Zero();  // (set by f)
      f.template value_and_jacobian<Tag, T>(xv, yv, J);
      // d = J x.d: the parts of x that are seeded symbols (unit seeds, known at compile time)
      // scatter J's columns; the others (general derivatives) multiply: row i of d is
      // sum_g J(i, g) x_g.d over the general columns g, a multiply-add of whole derivative arrays
      // (contiguous in the directions: SIMD along them, the row's accumulator in registers)
      using G = detail::GeneralColumns<Env, A>;
      for (int i = 0; i < rows; ++i)
        out[i] = S(yv[i]);
      if constexpr (G::count > 0) {
        // only the directions the general parts depend on (the others are zero for them) and the
        // entries of J that are not identically zero (F::jacobian_nonzero(), if F knows them)
        constexpr int ng = G::count;
        constexpr auto dirs = detail::general_directions<Env, A>();
        constexpr int kg = detail::count<K>(dirs);
        constexpr auto kept = detail::kept_directions<K, kg>(dirs);
        constexpr int k0 = kg > 0 ? kept[0] : 0;
        constexpr int kn = kg > 0 ? kept[std::size_t(kg - 1)] + 1 - k0 : 0;
        constexpr auto nz = detail::jacobian_nonzero<F>();
        // Two orders. With SIMD registers and the directions contiguous (their range [k0, k0 +
        // kn) at most a quarter larger than the kept set: the gaps' entries are zero for these
        // parts, a few wasted products): row by row, along the directions (the loop vectorizes,
        // the row's accumulators stay in registers). Otherwise (no SIMD, e.g. a Cortex-M, or
        // scattered directions): direction by direction, the rows' accumulators in registers.
        constexpr int lanes = arbor::simd_bytes / int(sizeof(detail::base_t<T>));
        if constexpr (lanes > 1 && kg > 0 && 4 * kn <= 5 * kg) {
          [&]<std::size_t... Is>(std::index_sequence<Is...>) {
            auto row = [&](auto ic) {
              constexpr int i = int(decltype(ic)::value);
              T acc[kn];  // acc[k - k0]: direction k
              for (int k = 0; k < kn; ++k)
                acc[k] = T(0);
              [&]<std::size_t... Gs>(std::index_sequence<Gs...>) {
                auto column = [&](auto gc) {
                  constexpr int j = G::cols[std::size_t(decltype(gc)::value)];
                  if constexpr (nz[std::size_t(j * rows + i)]) {
                    const T a = J(i, j);
                    const T* x = px[j]->d + k0;
                    for (int k = 0; k < kn; ++k)
                      acc[k] += a * x[k];
                  }
                };
                (column(std::integral_constant<std::size_t, Gs>{}), ...);
              }
              (std::make_index_sequence<std::size_t(ng)>{});
              for (int k = 0; k < kn; ++k)
                out[i].d[k0 + k] = acc[k];
            };
            (row(std::integral_constant<std::size_t, Is>{}), ...);
          }
          (std::make_index_sequence<std::size_t(rows)>{});
        } else {
          T jg[ng][rows];
          for (int g = 0; g < ng; ++g)
            for (int i = 0; i < rows; ++i)
              jg[g][i] = J(i, G::cols[std::size_t(g)]);
          for (int c = 0; c < kg; ++c) {
            const int k = kept[std::size_t(c)];
            T acc[rows];
            for (int i = 0; i < rows; ++i)
              acc[i] = T(0);
            [&]<std::size_t... Gs>(std::index_sequence<Gs...>) {
              auto column = [&](auto gc) {
                constexpr int g = int(decltype(gc)::value);
                constexpr int j = G::cols[std::size_t(g)];
                const T xj = px[j]->d[k];
                [&]<std::size_t... Is>(std::index_sequence<Is...>) {
                  auto entry = [&](auto ic) {
                    constexpr int i = int(decltype(ic)::value);
                    if constexpr (nz[std::size_t(j * rows + i)])
                      acc[i] += jg[g][i] * xj;
                  };
                  (entry(std::integral_constant<std::size_t, Is>{}), ...);
                }
                (std::make_index_sequence<std::size_t(rows)>{});
              };
              (column(std::integral_constant<std::size_t, Gs>{}), ...);
            }
            (std::make_index_sequence<std::size_t(ng)>{});
            for (int i = 0; i < rows; ++i)
              out[i].d[k] = acc[i];
          }
        }
      }
      detail::scatter_seeded<Env, A>(out, J);
    } else {
      const auto& x = arg.eval(env);
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

namespace detail {
/// A call node depends on the directions of its input.
template <class Tag, class F, class A>
struct Deps<CallExpr<Tag, F, A>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of<Env, A>();
  }
};
}  // namespace detail

}  // namespace arbor::ad
