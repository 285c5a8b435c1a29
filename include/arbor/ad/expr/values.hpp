// arbor: the value of an expression node (Values<S, N>, a plain array of N scalars), the
// Expression concept every node satisfies, and the conversions to and from Eigen vectors at the
// layer's boundaries. Compile-time only; a conversion copies N scalars.
//
// Values is a plain array rather than an Eigen vector because every (scalar, size) pair of an
// Eigen vector instantiates Eigen's whole class hierarchy, which dominates compile time and
// memory once expressions are evaluated at nested duals; Eigen types appear only at the
// boundaries (arguments, results, fn bodies, custom-derivative function objects).
#pragma once

#include <Eigen/Core>
#include <concepts>
#include <type_traits>

#include "arbor/spatial/fwd.hpp"

namespace arbor::ad {

/// The value of an expression node: N scalars of type S (a plain array, indexable by int).
template <class S, int N>
struct Values {
  static constexpr int size = N;  ///< number of elements
  S v[N];                         ///< the elements
  /// Element i.
  constexpr S& operator[](int i) { return v[i]; }
  /// Element i.
  constexpr const S& operator[](int i) const { return v[i]; }
};

/// An expression node: a type with `expression_tag`, `static constexpr int rows` (its size) and
/// `eval(env)` returning its value as Values<Env::Scalar, rows> (or a reference to one).
template <class E>
concept Expression = requires {
  typename std::remove_cvref_t<E>::expression_tag;
  { std::remove_cvref_t<E>::rows } -> std::convertible_to<int>;
};

namespace detail {

template <class>
inline constexpr bool always_false = false;

/// Values as an Eigen vector.
template <class S, int N>
VecN<S, N> to_eigen(const Values<S, N>& x) {
  VecN<S, N> r;
  for (int i = 0; i < N; ++i)
    r[i] = x[i];
  return r;
}

/// An Eigen N-vector (or a scalar if N == 1) as Values: the result of an fn body.
template <class S, int N, class R>
Values<S, N> to_values(const R& r) {
  Values<S, N> v;
  if constexpr (std::is_base_of_v<Eigen::EigenBase<R>, R>) {
    static_assert(R::RowsAtCompileTime == N && R::ColsAtCompileTime == 1,
                  "an fn body must return a vector of Nout rows");
    const VecN<S, N> e = r;
    for (int i = 0; i < N; ++i)
      v[i] = e[i];
  } else {
    static_assert(N == 1, "an fn body returning a scalar needs Nout == 1");
    v[0] = S(r);
  }
  return v;
}

}  // namespace detail
}  // namespace arbor::ad
