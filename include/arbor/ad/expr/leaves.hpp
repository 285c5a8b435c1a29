// arbor: the leaves of an expression: Symbol<Id, N> (argument Id of an evaluation, an N-vector)
// and run-time constants (constant(v), parameters fixed at construction). A symbol costs
// nothing (it returns a reference to its argument); a constant is lifted to the evaluation's
// scalar, or enters the arithmetic nodes as a plain number (no lifting, no dual products).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/expr/scalar.hpp"
#include "arbor/ad/expr/values.hpp"

namespace arbor::ad {

/// Argument Id of an evaluation, an N-vector (an empty type: declare `constexpr Symbol<0, 3> x;`).
template <int Id, int N>
struct Symbol {
  static_assert(Id >= 0 && N >= 1, "Symbol<Id, N> needs Id >= 0 and N >= 1");
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = N;  ///< size
  static constexpr int id = Id;   ///< argument index
  /// The argument's value.
  template <class Env>
  const auto& eval(const Env& env) const {
    const auto& v = env.template arg<Id>();
    static_assert(std::remove_cvref_t<decltype(v)>::size == N,
                  "the argument's size differs from its Symbol's N");
    return v;
  }
};

/// A vector of run-time constants (parameters fixed at construction).
template <int N>
struct ConstantExpr {
  using expression_tag = void;                          ///< marks an expression node
  static constexpr int rows = N;                        ///< size
  static constexpr bool is_constant_expression = true;  ///< used without lifting in binary nodes
  std::array<double, std::size_t(N)> value;             ///< the constants
  /// The constants at scalar S (zero derivatives).
  template <class Env>
  Values<typename Env::Scalar, N> eval(const Env&) const {
    using S = typename Env::Scalar;
    Values<S, N> r;
    for (int i = 0; i < N; ++i)
      r[i] = detail::lift_constant<S>(detail::base_t<S>(value[std::size_t(i)]));
    return r;
  }
};

namespace detail {
/// True for ConstantExpr nodes (their values are known numbers, used without lifting).
template <class E>
inline constexpr bool is_constant_expr_v = requires {
  E::is_constant_expression;
};
}  // namespace detail

/// A fixed-size Eigen column vector type.
template <class V>
concept FixedVector = std::is_base_of_v<Eigen::EigenBase<V>, V> && V::ColsAtCompileTime == 1 &&
                      V::RowsAtCompileTime != Eigen::Dynamic;

/// A constant vector expression (parameters fixed at construction) from an Eigen vector.
template <FixedVector V>
ConstantExpr<V::RowsAtCompileTime> constant(const V& v) {
  ConstantExpr<V::RowsAtCompileTime> c{};
  const Eigen::Matrix<double, V::RowsAtCompileTime, 1> d = v.template cast<double>();
  for (int i = 0; i < V::RowsAtCompileTime; ++i)
    c.value[std::size_t(i)] = d[i];
  return c;
}
/// A constant scalar expression (1 row).
template <Arithmetic A>
ConstantExpr<1> constant(A a) {
  return ConstantExpr<1>{{double(a)}};
}

}  // namespace arbor::ad
