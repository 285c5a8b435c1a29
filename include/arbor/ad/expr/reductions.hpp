// arbor: reductions of expressions to one row: dot(a, b), squared_norm(a), sum(a). Each sum
// starts from its first term (no addition to 0); constant weights (dot with constant(c)) scale
// each component once. Cost: n products and n - 1 additions (sum: n - 1 additions).
#pragma once

#include <cstddef>

#include "arbor/ad/expr/leaves.hpp"
#include "arbor/ad/expr/scalar.hpp"
#include "arbor/ad/expr/values.hpp"

namespace arbor::ad {

/// Inner product of two expressions of equal size (1 row).
template <Expression L, Expression R>
struct DotExpr {
  static_assert(L::rows == R::rows, "dot needs operands of equal size");
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = 1;  ///< size
  L lhs;                          ///< left operand
  R rhs;                          ///< right operand
  /// sum_i lhs_i rhs_i, starting from the first term.
  template <class Env>
  Values<typename Env::Scalar, 1> eval(const Env& env) const {
    using S = typename Env::Scalar;
    using B = detail::base_t<S>;
    Values<S, 1> r;
    constexpr bool lc = detail::is_constant_expr_v<L>;
    constexpr bool rc = detail::is_constant_expr_v<R>;
    if constexpr (lc && rc) {
      double s = 0;
      for (int i = 0; i < L::rows; ++i)
        s += lhs.value[std::size_t(i)] * rhs.value[std::size_t(i)];
      r[0] = detail::lift_constant<S>(B(s));
    } else if constexpr (lc) {
      r[0] = weighted_sum<S>(lhs.value, rhs.eval(env));
    } else if constexpr (rc) {
      r[0] = weighted_sum<S>(rhs.value, lhs.eval(env));
    } else {
      const auto& a = lhs.eval(env);
      const auto& b = rhs.eval(env);
      S acc = a[0] * b[0];
      for (int i = 1; i < L::rows; ++i)
        acc += a[i] * b[i];
      r[0] = acc;
    }
    return r;
  }

 private:
  template <class S, class W, class X>
  static S weighted_sum(const W& w, const X& x) {
    using B = detail::base_t<S>;
    S acc = detail::scale(S(x[0]), B(w[0]));
    for (int i = 1; i < L::rows; ++i)
      acc += detail::scale(S(x[i]), B(w[std::size_t(i)]));
    return acc;
  }
};

/// Squared Euclidean norm of an expression (1 row).
template <Expression A>
struct SquaredNormExpr {
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = 1;  ///< size
  A arg;                          ///< operand
  /// sum_i a_i^2.
  template <class Env>
  Values<typename Env::Scalar, 1> eval(const Env& env) const {
    using S = typename Env::Scalar;
    const auto& a = arg.eval(env);
    S acc = a[0] * a[0];
    for (int i = 1; i < A::rows; ++i)
      acc += a[i] * a[i];
    Values<S, 1> r;
    r[0] = acc;
    return r;
  }
};

/// Sum of the elements of an expression (1 row).
template <Expression A>
struct SumExpr {
  using expression_tag = void;    ///< marks an expression node
  static constexpr int rows = 1;  ///< size
  A arg;                          ///< operand
  /// sum_i a_i.
  template <class Env>
  Values<typename Env::Scalar, 1> eval(const Env& env) const {
    using S = typename Env::Scalar;
    const auto& a = arg.eval(env);
    S acc = a[0];
    for (int i = 1; i < A::rows; ++i)
      acc += a[i];
    Values<S, 1> r;
    r[0] = acc;
    return r;
  }
};

/// Inner product a^T b (1 row).
template <Expression L, Expression R>
DotExpr<L, R> dot(const L& a, const R& b) {
  return {a, b};
}
/// Squared Euclidean norm |a|^2 (1 row).
template <Expression A>
SquaredNormExpr<A> squared_norm(const A& a) {
  return {a};
}
/// Sum of the elements (1 row).
template <Expression A>
SumExpr<A> sum(const A& a) {
  return {a};
}

}  // namespace arbor::ad
