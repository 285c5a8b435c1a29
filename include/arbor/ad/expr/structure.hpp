// arbor: the derivative directions an expression node can depend on, known at compile time
// (structure-aware forward mode), and the compressed scalars that carry only those directions.
//
// In a derivative evaluation at S = Dual<T, n> every argument element is seeded along its own
// direction, so a node's derivatives are structurally zero outside the directions of the
// arguments it reads: a symbol depends on its argument's directions, a segment of a symbol on
// the segment's, a parameter (an argument not differentiated) and a constant on none, every
// other node on the union of its operands'. Node types not listed here (user-defined nodes,
// ocp::rk4) and arguments whose derivatives are not unit seeds (rk4's substituted state) count
// as depending on every direction: the sets are supersets, never wrong.
//
// The fn boundary (boundaries.hpp) uses them: its body, generic user code, runs at
// Compressed<S, K, L>, a dual of only the K directions its inputs depend on (nested for the L
// dual levels the evaluation owns: Hessians compress both), so its cost follows K, not n; the
// result is scattered back with zeros elsewhere. Cost of the change of scalar: one copy per
// input element and direction kept, one per output element and direction of S.
#pragma once

#include <array>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/expr/blocks.hpp"
#include "arbor/ad/expr/constant_matrix.hpp"
#include "arbor/ad/expr/elementwise.hpp"
#include "arbor/ad/expr/leaves.hpp"
#include "arbor/ad/expr/reductions.hpp"
#include "arbor/ad/expr/values.hpp"
#include "arbor/core/config.hpp"

namespace arbor::ad::detail {

/// Whether argument Id's outer-level derivatives in Env are its unit seeds (or zero, for a
/// parameter): Env::unit_seeds<Id>() where the environment says so per argument, else
/// Env::seeded.
template <class Env, int Id>
constexpr bool unit_seeds() {
  if constexpr (requires { Env::template unit_seeds<Id>(); })
    return Env::template unit_seeds<Id>();
  else
    return Env::seeded;
}

/// The number of dual levels of Env::Scalar that this evaluation seeded (1 for Jacobians, 2 for
/// Hessians; 0 for a plain evaluation, or an environment that does not say).
template <class Env>
constexpr int env_levels() {
  if constexpr (requires { Env::levels; })
    return Env::levels;
  else
    return 0;
}

/// Number of dual levels of S.
template <class S>
constexpr int dual_depth() {
  if constexpr (is_dual_v<S>)
    return 1 + dual_depth<typename S::Value>();
  else
    return 0;
}

/// Directions of S's outermost level (0 when S is not a dual).
template <class S>
constexpr int outer_directions() {
  if constexpr (is_dual_v<S>)
    return S::directions;
  else
    return 0;
}

/// A set of directions of a dual with N directions.
template <int N>
using DirSet = std::array<bool, std::size_t(N)>;

template <int N>
constexpr DirSet<N> all_directions() {
  DirSet<N> r{};
  for (auto& b : r)
    b = true;
  return r;
}
template <int N>
constexpr DirSet<N> unite(DirSet<N> a, const DirSet<N>& b) {
  for (std::size_t k = 0; k < std::size_t(N); ++k)
    a[k] = a[k] || b[k];
  return a;
}
template <int N>
constexpr int count(const DirSet<N>& a) {
  int c = 0;
  for (bool b : a)
    c += b ? 1 : 0;
  return c;
}

/// Deps<E>::get<Env>(): a superset of the outer-level directions of E's value in Env. Primary:
/// every direction (unknown nodes).
template <class E>
struct Deps {
  template <class Env>
  static constexpr auto get() {
    return all_directions<outer_directions<typename Env::Scalar>()>();
  }
};

/// The directions E depends on in Env.
template <class Env, class E>
constexpr auto deps_of() {
  return Deps<std::remove_cvref_t<E>>::template get<Env>();
}

/// The union of the directions of E...
template <class Env, class... E>
constexpr auto deps_of_all() {
  constexpr int n = outer_directions<typename Env::Scalar>();
  DirSet<n> r{};
  ((r = unite<n>(r, deps_of<Env, E>())), ...);
  return r;
}

/// Elements [Start, Start + Len) of argument Id: their seeds, or every direction.
template <class Env, int Id, int Start, int Len>
constexpr auto argument_directions() {
  constexpr int n = outer_directions<typename Env::Scalar>();
  if constexpr (!unit_seeds<Env, Id>()) {
    return all_directions<n>();
  } else {
    DirSet<n> r{};
    constexpr int off = Env::template offset<Id>();
    if constexpr (off >= 0)
      for (int j = Start; j < Start + Len; ++j)
        r[std::size_t(off + j)] = true;
    return r;
  }
}

template <int Id, int N>
struct Deps<Symbol<Id, N>> {
  template <class Env>
  static constexpr auto get() {
    return argument_directions<Env, Id, 0, N>();
  }
};
template <int N>
struct Deps<ConstantExpr<N>> {
  template <class Env>
  static constexpr auto get() {
    return DirSet<outer_directions<typename Env::Scalar>()>{};
  }
};
template <int St, int L, class A>
struct Deps<SegmentExpr<St, L, A>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of<Env, A>();
  }
};
template <int St, int L, int Id, int N>
struct Deps<SegmentExpr<St, L, Symbol<Id, N>>> {
  template <class Env>
  static constexpr auto get() {
    return argument_directions<Env, Id, St, L>();
  }
};
template <class... A>
struct Deps<CatExpr<A...>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of_all<Env, A...>();
  }
};
template <class Op, class A>
struct Deps<UnaryExpr<Op, A>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of<Env, A>();
  }
};
template <class Op, class L, class R>
struct Deps<BinaryExpr<Op, L, R>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of_all<Env, L, R>();
  }
};
template <class L, class R>
struct Deps<DotExpr<L, R>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of_all<Env, L, R>();
  }
};
template <class A>
struct Deps<SquaredNormExpr<A>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of<Env, A>();
  }
};
template <class A>
struct Deps<SumExpr<A>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of<Env, A>();
  }
};
template <class K, class A>
struct Deps<MatVecExpr<K, A>> {
  template <class Env>
  static constexpr auto get() {
    return deps_of<Env, A>();
  }
};

// ---- compressed scalars ----------------------------------------------------------------------

/// S with its L outer dual levels reduced to K directions each (K == 0: the levels removed).
template <class S, int K, int L>
struct CompressedScalar {
  using type = S;
};
template <class T, int N, int K, int L>
requires(L >= 1) struct CompressedScalar<Dual<T, N>, K, L> {
  using inner = typename CompressedScalar<T, K, L - 1>::type;
  using type = std::conditional_t<K == 0, inner, Dual<inner, (K > 0 ? K : 1)>>;
};
template <class S, int K, int L>
using Compressed = typename CompressedScalar<S, K, L>::type;

/// The number of directions of a compressed dual keeping K of N directions of base scalar B:
/// K rounded up to whole SIMD registers (a dual whose directions fill whole registers is
/// vectorised without remainder loops; the padding directions are zero), at most N; K where
/// there is no SIMD (every direction costs its instructions).
template <class B, int N, int K>
constexpr int padded_directions() {
  constexpr int lanes = arbor::simd_bytes / int(sizeof(B));
  if constexpr (K == 0 || lanes <= 1) {
    return K;
  } else {
    constexpr int p = (K + lanes - 1) / lanes * lanes;
    return p < N ? p : N;
  }
}

/// The kept directions in order (compressed index -> direction of S), then -1 for the padding
/// up to P.
template <int N, int P>
constexpr std::array<int, std::size_t(P)> kept_directions(const DirSet<N>& mask) {
  std::array<int, std::size_t(P)> idx{};
  for (auto& i : idx)
    i = -1;
  int a = 0;
  for (int k = 0; k < N; ++k)
    if (mask[std::size_t(k)])
      idx[std::size_t(a++)] = k;
  return idx;
}
/// Direction of S -> compressed index (-1: dropped, structurally zero).
template <int N>
constexpr std::array<int, std::size_t(N)> compressed_positions(const DirSet<N>& mask) {
  std::array<int, std::size_t(N)> pos{};
  int a = 0;
  for (int k = 0; k < N; ++k)
    pos[std::size_t(k)] = mask[std::size_t(k)] ? a++ : -1;
  return pos;
}

/// s at the compressed scalar C: L levels, each reduced to the directions Idx (a std::array:
/// the kept direction of each compressed one, -1 for padding (zero); empty: the levels removed).
/// Unrolled at compile time.
template <int L, auto Idx, class C, class S>
C gather(const S& s) {
  constexpr std::size_t K = Idx.size();
  if constexpr (L == 0) {
    return s;
  } else if constexpr (K == 0) {
    return gather<L - 1, Idx, C>(s.v);
  } else {
    using CV = typename C::Value;
    C c;
    c.v = gather<L - 1, Idx, CV>(s.v);
    [&]<std::size_t... A>(std::index_sequence<A...>) {
      auto one = [&](auto a) {
        constexpr int k = Idx[decltype(a)::value];
        if constexpr (k >= 0)
          c.d[decltype(a)::value] = gather<L - 1, Idx, CV>(s.d[k]);
        else
          c.d[decltype(a)::value] = CV{};
      };
      (one(std::integral_constant<std::size_t, A>{}), ...);
    }
    (std::make_index_sequence<K>{});
    return c;
  }
}

/// c (compressed by gather<L, Idx>) back at S: Pos maps each direction of S to its compressed
/// index (-1: dropped, zero); K the number of compressed directions. Unrolled at compile time.
template <int L, int K, auto Pos, class S, class C>
S scatter(const C& c) {
  if constexpr (L == 0) {
    return c;
  } else {
    using SV = typename S::Value;
    constexpr std::size_t N = Pos.size();
    static_assert(std::size_t(S::directions) == N, "compressed levels need equal directions");
    if constexpr (K == 0) {
      // nothing kept: c is the value alone, every derivative zero (c.d is not named here, where
      // it does not exist: Clang checks a discarded branch's non-dependent code)
      return S(scatter<L - 1, K, Pos, SV>(c));
    } else {
      S r;
      r.v = scatter<L - 1, K, Pos, SV>(c.v);
      [&]<std::size_t... D>(std::index_sequence<D...>) {
        auto one = [&](auto k) {
          constexpr int a = Pos[decltype(k)::value];
          if constexpr (a >= 0)
            r.d[decltype(k)::value] = scatter<L - 1, K, Pos, SV>(c.d[a]);
          else
            r.d[decltype(k)::value] = SV{};
        };
        (one(std::integral_constant<std::size_t, D>{}), ...);
      }
      (std::make_index_sequence<N>{});
      return r;
    }
  }
}

/// RowDeps<E>::get<Env>(): per row of E, a superset of the outer-level directions it depends on
/// (a Jacobian's structural pattern by rows). Primary: every row has E's directions; a cat stacks
/// its parts' rows; a seeded symbol (or a segment of one) has one direction per row.
template <class E>
struct RowDeps {
  template <class Env>
  static constexpr auto get() {
    constexpr int n = outer_directions<typename Env::Scalar>();
    std::array<DirSet<n>, std::size_t(E::rows)> r{};
    for (auto& row : r)
      row = deps_of<Env, E>();
    return r;
  }
};
template <int St, int L, int Id, int N>
struct RowDeps<SegmentExpr<St, L, Symbol<Id, N>>> {
  template <class Env>
  static constexpr auto get() {
    using Rows = std::array<DirSet<outer_directions<typename Env::Scalar>()>, std::size_t(L)>;
    // (Rows spelled out: deduced from a single element, std::array{...} would copy it when L = 1)
    return []<std::size_t... I>(std::index_sequence<I...>) {
      return Rows{argument_directions<Env, Id, St + int(I), 1>()...};
    }
    (std::make_index_sequence<std::size_t(L)>{});
  }
};
template <int Id, int N>
struct RowDeps<Symbol<Id, N>> {
  template <class Env>
  static constexpr auto get() {
    return RowDeps<SegmentExpr<0, N, Symbol<Id, N>>>::template get<Env>();
  }
};
template <class... A>
struct RowDeps<CatExpr<A...>> {
  template <class Env>
  static constexpr auto get() {
    constexpr int n = outer_directions<typename Env::Scalar>();
    std::array<DirSet<n>, std::size_t((A::rows + ...))> r{};
    std::size_t at = 0;
    auto put = [&](const auto& part) {
      for (const auto& row : part)
        r[at++] = row;
    };
    (put(RowDeps<A>::template get<Env>()), ...);
    return r;
  }
};

/// The directions each row of E depends on in Env (std::array of E::rows DirSets).
template <class Env, class E>
constexpr auto row_deps() {
  return RowDeps<std::remove_cvref_t<E>>::template get<Env>();
}

/// A row pattern as index lists: cols[i][0 .. count[i]) are the directions row i depends on.
template <int M, int N>
struct RowPattern {
  std::array<int, std::size_t(M)> count{};                             ///< per row
  std::array<std::array<int, std::size_t(N)>, std::size_t(M)> cols{};  ///< per row, ascending
};
template <int M, int N>
constexpr RowPattern<M, N> row_pattern(const std::array<DirSet<N>, std::size_t(M)>& deps) {
  RowPattern<M, N> p{};
  for (std::size_t i = 0; i < std::size_t(M); ++i)
    for (int k = 0; k < N; ++k)
      if (deps[i][std::size_t(k)])
        p.cols[i][std::size_t(p.count[i]++)] = k;
  return p;
}

}  // namespace arbor::ad::detail
