// arbor: products K x of an expression x with a matrix K of compile-time constants (mul<K>(x)
// or K{} * x). The product is spatial/constant.hpp's (cst::row_n, the engine of the RBD code's
// constant products): zero entries generate no code, +-1 entries become additions and
// subtractions, and any other entry scales each component of a (nested) dual once by a plain
// number (detail::Coefficient). Cost per row: one multiplication per entry other than 0 and +-1,
// one addition per further nonzero entry.
//
// K is any type with `static constexpr int rows, cols` and `static constexpr double at(int r,
// int c)` (e.g. reading a static constexpr array, or ConstMatrix<2, 3, {...}> where the compiler
// supports floating-point class-type template arguments).
#pragma once

#include <array>
#include <concepts>
#include <cstddef>
#include <utility>

#include "arbor/ad/expr/scalar.hpp"
#include "arbor/ad/expr/values.hpp"
#include "arbor/core/static_for.hpp"
#include "arbor/spatial/constant.hpp"

namespace arbor::ad {

/// A matrix of compile-time constants: static constexpr rows, cols and at(r, c).
template <class K>
concept CompileTimeMatrix = requires {
  { K::rows } -> std::convertible_to<int>;
  { K::cols } -> std::convertible_to<int>;
  { K::at(0, 0) } -> std::convertible_to<double>;
};

#if defined(__cpp_nontype_template_args) && __cpp_nontype_template_args >= 201911L
/// A compile-time matrix from its entries in row-major order: ConstMatrix<2, 2, {1.0, 0.0, ...}>
/// (needs floating-point class-type template arguments: GCC >= 11, Clang >= 18).
template <int Rows, int Cols, std::array<double, std::size_t(Rows) * std::size_t(Cols)> Entries>
struct ConstMatrix {
  static constexpr int rows = Rows;  ///< number of rows
  static constexpr int cols = Cols;  ///< number of columns
  /// Entry (r, c).
  static constexpr double at(int r, int c) { return Entries[std::size_t(r * Cols + c)]; }
};
#endif

/// The transpose of a compile-time matrix K.
template <CompileTimeMatrix K>
struct TransposedMatrix {
  static constexpr int rows = K::cols;  ///< number of rows
  static constexpr int cols = K::rows;  ///< number of columns
  /// Entry (r, c) = K(c, r).
  static constexpr double at(int r, int c) { return K::at(c, r); }
};

namespace detail {

/// A constant of the innermost scalar type B as the factor of cst::scaled (which writes
/// x * S(c) for an entry c other than 0 and +-1): each component of x is scaled once, where a
/// product with the dual S(c) would cost a dual product.
template <class B>
struct Coefficient {
  B c;  ///< the constant
  /// The constant c.
  constexpr explicit Coefficient(double v) : c(B(v)) {}
};
/// x * c, one product per component of x.
template <class S, class B>
S operator*(const S& x, const Coefficient<B>& k) {
  return scale(x, k.c);
}

}  // namespace detail

/// Product of a compile-time matrix K and an expression.
template <CompileTimeMatrix K, Expression A>
struct MatVecExpr {
  static_assert(K::cols == A::rows, "mul<K>(x): K::cols must equal the size of x");
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = K::rows;  ///< size
  A arg;                                ///< operand
  /// K x with zero entries skipped and +-1 entries as additions/subtractions (cst::row_n).
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using S = typename Env::Scalar;
    using B = detail::base_t<S>;
    const auto& x = arg.eval(env);
    const auto zero = [] { return detail::lift_constant<S>(B(0)); };
    Values<S, rows> r;
    static_for<rows>([&](auto i) {
      r[i] = spatial::cst::row_n<detail::Coefficient<B>, K, decltype(i)::value>(
          x, zero, std::make_integer_sequence<int, K::cols>{});
    });
    return r;
  }
};

/// K a for a compile-time matrix K (zero entries cost nothing).
template <CompileTimeMatrix K, Expression A>
MatVecExpr<K, A> mul(const A& a) {
  return {a};
}
/// K a for a compile-time matrix K, written `K{} * a`.
template <CompileTimeMatrix K, Expression A>
MatVecExpr<K, A> operator*(const K&, const A& a) {
  return {a};
}

}  // namespace arbor::ad
