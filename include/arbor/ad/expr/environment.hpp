// arbor: the environment of an evaluation: the arguments' values at the evaluation's scalar S,
// seeded for differentiation, and where each argument's derivative directions start. Built once
// per evaluation by the entry points (evaluate.hpp); nodes read it through env.arg<Id>() and
// env.offset<Id>(). Cost: one copy (and seeding) of every argument element.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

#include "arbor/ad/expr/scalar.hpp"
#include "arbor/ad/expr/values.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::ad::detail {

/// Environment of an evaluation: the argument values at scalar S (already seeded). When Levels >
/// 0, the Levels outermost dual levels of S belong to this evaluation (1: Jacobians, 2: Hessians,
/// the same seeds at each) and argument Id occupies directions Offsets[Id] .. Offsets[Id] + N - 1
/// (Offsets[Id] < 0: a parameter, zero derivatives).
template <class S, int Levels, auto Offsets, class... V>
struct RootEnv {
  using Scalar = S;                           ///< scalar type of the evaluation
  static constexpr bool seeded = Levels > 0;  ///< the outer dual level is this evaluation's
  static constexpr int levels = Levels;       ///< dual levels seeded by this evaluation
  static constexpr int arguments = int(sizeof...(V));  ///< number of arguments
  std::tuple<V...> args;                               ///< argument values, Values<S, N_i>
  /// First derivative direction of argument Id (< 0: not differentiated).
  template <int Id>
  static constexpr int offset() {
    return Offsets[std::size_t(Id)];
  }
  /// True when the outer-level derivatives of argument Id are its seeds: unit vectors from
  /// offset<Id>() (zero for a parameter). Here: every argument of a seeded evaluation.
  template <int Id>
  static constexpr bool unit_seeds() {
    return seeded;
  }
  /// Value of argument Id.
  template <int Id>
  const auto& arg() const {
    static_assert(Id >= 0 && Id < int(sizeof...(V)),
                  "a Symbol<Id, N> has no argument: pass one value per Id 0, 1, ...");
    return std::get<Id>(args);
  }
  /// A let placeholder outside its let: a compile-time error.
  template <class Key>
  void bound() const {
    static_assert(always_false<Key>, "a let placeholder was used outside the body of its let");
  }
};

/// Size and scalar of an argument: an Eigen column vector, or a plain scalar (size 1).
template <class A, bool IsEigen = std::is_base_of_v<Eigen::EigenBase<A>, A>>
struct ArgTraits {
  static constexpr int rows = 1;
  using Scalar = A;
};
template <class A>
struct ArgTraits<A, true> {
  static_assert(A::ColsAtCompileTime == 1 && A::RowsAtCompileTime != Eigen::Dynamic,
                "arguments must be fixed-size column vectors");
  static constexpr int rows = A::RowsAtCompileTime;
  using Scalar = typename A::Scalar;
};

/// The common scalar and the sizes of a list of arguments.
template <class... A>
struct ArgPack {
  using Scalar = std::common_type_t<typename ArgTraits<A>::Scalar...>;
  static constexpr std::array<int, sizeof...(A)> sizes{ArgTraits<A>::rows...};
};
template <>
struct ArgPack<> {
  using Scalar = double;
  static constexpr std::array<int, 0> sizes{};
};

/// The scalar of the arguments (the scalar of the results).
template <class... A>
using scalar_of_args = typename ArgPack<std::remove_cvref_t<A>...>::Scalar;

/// True when Wrt lists valid, distinct argument Ids.
template <std::size_t K, int... Wrt>
consteval bool wrt_valid() {
  const int ids[] = {Wrt..., 0};
  for (std::size_t a = 0; a < sizeof...(Wrt); ++a) {
    if (ids[a] < 0 || ids[a] >= int(K))
      return false;
    for (std::size_t b = 0; b < a; ++b)
      if (ids[a] == ids[b])
        return false;
  }
  return true;
}

/// Offset of each argument in the stacked derivative directions, -1 when not differentiated.
/// All arguments in Id order when Wrt is empty, otherwise the listed Ids in the listed order.
template <std::size_t K, int... Wrt>
consteval std::array<int, K> wrt_offsets(const std::array<int, K>& sizes) {
  std::array<int, K> off{};
  for (auto& o : off)
    o = -1;
  int pos = 0;
  if constexpr (sizeof...(Wrt) == 0) {
    for (std::size_t i = 0; i < K; ++i) {
      off[i] = pos;
      pos += sizes[i];
    }
  } else {
    for (int id : {Wrt...}) {
      off[std::size_t(id)] = pos;
      pos += sizes[std::size_t(id)];
    }
  }
  return off;
}

/// Number of derivative directions.
template <std::size_t K>
consteval int wrt_size(const std::array<int, K>& sizes, const std::array<int, K>& off) {
  int n = 0;
  for (std::size_t i = 0; i < K; ++i)
    if (off[i] >= 0)
      n += sizes[i];
  return n;
}

/// One argument at scalar S: constants (Offset < 0) or seeded variables.
template <class S, class T, int Offset, class A>
Values<S, ArgTraits<A>::rows> make_arg(const A& a) {
  constexpr int n = ArgTraits<A>::rows;
  Values<S, n> r;
  if constexpr (std::is_base_of_v<Eigen::EigenBase<A>, A>) {
    const VecN<typename A::Scalar, n> av = a;
    for (int j = 0; j < n; ++j) {
      if constexpr (Offset < 0)
        r[j] = lift_argument<S, T>(T(av[j]));
      else
        r[j] = seed_argument<S, T>(T(av[j]), Offset + j);
    }
  } else {
    if constexpr (Offset < 0)
      r[0] = lift_argument<S, T>(T(a));
    else
      r[0] = seed_argument<S, T>(T(a), Offset);
  }
  return r;
}

/// Number of dual levels S adds above T (S = Dual<...Dual<T, n>..., n>).
template <class S, class T>
constexpr int dual_levels_above() {
  if constexpr (std::is_same_v<S, T>)
    return 0;
  else
    return 1 + dual_levels_above<typename S::Value, T>();
}

/// The root environment of an evaluation at S of arguments of scalar T.
template <class S, class T, bool Seeded, auto Offsets, std::size_t... I, class... A>
RootEnv<S, Seeded ? dual_levels_above<S, T>() : 0, Offsets, Values<S, ArgTraits<A>::rows>...>
make_env(std::index_sequence<I...>, const A&... a) {
  return {std::tuple<Values<S, ArgTraits<A>::rows>...>(make_arg<S, T, Offsets[I]>(a)...)};
}

}  // namespace arbor::ad::detail
