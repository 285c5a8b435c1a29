// arbor: elementwise expressions: + - * / (a 1-row operand or a plain number is broadcast),
// unary -, sin, cos, sqrt. A constant operand (constant(...) or a number) enters as a number of
// the innermost scalar type: x * c scales each component of a dual once, x + c changes only the
// value. Cost: one operation (at the evaluation's scalar) per element.
#pragma once

#include <cstddef>
#include <type_traits>

#include "arbor/ad/dual.hpp"
#include "arbor/ad/expr/leaves.hpp"
#include "arbor/ad/expr/scalar.hpp"
#include "arbor/ad/expr/values.hpp"
#include "arbor/core/math.hpp"

namespace arbor::ad {

namespace detail {

// Elementwise operations: apply (both operands variable), const_left (c op x), const_right
// (x op c) with c a constant of the innermost scalar type.
struct AddOp {
  template <class S>
  static S apply(const S& a, const S& b) {
    return a + b;
  }
  template <class B, class S>
  static S const_left(const B& c, const S& x) {
    return shift(x, c);
  }
  template <class S, class B>
  static S const_right(const S& x, const B& c) {
    return shift(x, c);
  }
};
struct SubOp {
  template <class S>
  static S apply(const S& a, const S& b) {
    return a - b;
  }
  template <class B, class S>
  static S const_left(const B& c, const S& x) {
    return rsub(c, x);
  }
  template <class S, class B>
  static S const_right(const S& x, const B& c) {
    return shift(x, B(-c));
  }
};
struct MulOp {
  template <class S>
  static S apply(const S& a, const S& b) {
    return a * b;
  }
  template <class B, class S>
  static S const_left(const B& c, const S& x) {
    return scale(x, c);
  }
  template <class S, class B>
  static S const_right(const S& x, const B& c) {
    return scale(x, c);
  }
};
struct DivOp {
  template <class S>
  static S apply(const S& a, const S& b) {
    return a / b;
  }
  template <class B, class S>
  static S const_left(const B& c, const S& x) {
    return rdiv(c, x);
  }
  template <class S, class B>
  static S const_right(const S& x, const B& c) {
    return divide(x, c);
  }
};
struct NegOp {
  template <class S>
  static S apply(const S& x) {
    return -x;
  }
};
struct SinOp {
  template <class S>
  static S apply(const S& x) {
    return arbor::sin(x);
  }
};
struct CosOp {
  template <class S>
  static S apply(const S& x) {
    return arbor::cos(x);
  }
};
struct SqrtOp {
  template <class S>
  static S apply(const S& x) {
    return arbor::sqrt(x);
  }
};

}  // namespace detail

/// An elementwise function of one expression.
template <class Op, Expression A>
struct UnaryExpr {
  using expression_tag = void;          ///< marks an expression node
  static constexpr int rows = A::rows;  ///< size
  A arg;                                ///< operand
  /// Op applied to every element.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    const auto& a = arg.eval(env);
    Values<typename Env::Scalar, rows> r;
    for (int i = 0; i < rows; ++i)
      r[i] = Op::apply(a[i]);
    return r;
  }
};

/// An elementwise binary operation; a 1-row operand is broadcast against an N-row one.
template <class Op, Expression L, Expression R>
struct BinaryExpr {
  static_assert(L::rows == R::rows || L::rows == 1 || R::rows == 1,
                "elementwise operands need equal sizes (or one of size 1)");
  using expression_tag = void;                                        ///< marks an expression node
  static constexpr int rows = L::rows > R::rows ? L::rows : R::rows;  ///< size
  L lhs;                                                              ///< left operand
  R rhs;                                                              ///< right operand
  /// The elementwise result; constant operands enter as numbers (no lifting to S).
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    using S = typename Env::Scalar;
    using B = detail::base_t<S>;
    constexpr bool lc = detail::is_constant_expr_v<L>;
    constexpr bool rc = detail::is_constant_expr_v<R>;
    Values<S, rows> r;
    if constexpr (lc && !rc) {
      const auto& b = rhs.eval(env);
      for (int i = 0; i < rows; ++i)
        r[i] = Op::const_left(B(lhs.value[std::size_t(li(i))]), S(b[ri(i)]));
    } else if constexpr (!lc && rc) {
      const auto& a = lhs.eval(env);
      for (int i = 0; i < rows; ++i)
        r[i] = Op::const_right(S(a[li(i)]), B(rhs.value[std::size_t(ri(i))]));
    } else {
      const auto& a = lhs.eval(env);
      const auto& b = rhs.eval(env);
      for (int i = 0; i < rows; ++i)
        r[i] = Op::apply(S(a[li(i)]), S(b[ri(i)]));
    }
    return r;
  }

 private:
  static constexpr int li(int i) { return L::rows == 1 ? 0 : i; }
  static constexpr int ri(int i) { return R::rows == 1 ? 0 : i; }
};

/// An operand of the binary operators: an expression or a plain number (a broadcast constant).
template <class X>
concept Operand = Expression<X> || Arithmetic<X>;

/// At least one of L and R is an expression.
template <class L, class R>
concept AnyExpression = Expression<L> || Expression<R>;

/// R and L are operands of a binary operator (L op R): operands, at least one an expression.
template <class R, class L>
concept OperandWith = Operand<L> && Operand<R> && AnyExpression<L, R>;

namespace detail {
template <class E>
auto as_expression(const E& e) {
  if constexpr (Expression<E>)
    return e;
  else
    return constant(e);
}
template <class Op, class L, class R>
auto binary(const L& l, const R& r) {
  using LE = decltype(as_expression(l));
  using RE = decltype(as_expression(r));
  return BinaryExpr<Op, LE, RE>{as_expression(l), as_expression(r)};
}
}  // namespace detail

/// Elementwise sum (a 1-row operand or a number is broadcast).
template <class L, OperandWith<L> R>
auto operator+(const L& l, const R& r) {
  return detail::binary<detail::AddOp>(l, r);
}
/// Elementwise difference (a 1-row operand or a number is broadcast).
template <class L, OperandWith<L> R>
auto operator-(const L& l, const R& r) {
  return detail::binary<detail::SubOp>(l, r);
}
/// Elementwise product; scalar * vector when one side has 1 row or is a number.
template <class L, OperandWith<L> R>
auto operator*(const L& l, const R& r) {
  return detail::binary<detail::MulOp>(l, r);
}
/// Elementwise quotient (a 1-row operand or a number is broadcast).
template <class L, OperandWith<L> R>
auto operator/(const L& l, const R& r) {
  return detail::binary<detail::DivOp>(l, r);
}
/// Elementwise negation.
template <Expression A>
UnaryExpr<detail::NegOp, A> operator-(const A& a) {
  return {a};
}
/// Elementwise sine.
template <Expression A>
UnaryExpr<detail::SinOp, A> sin(const A& a) {
  return {a};
}
/// Elementwise cosine.
template <Expression A>
UnaryExpr<detail::CosOp, A> cos(const A& a) {
  return {a};
}
/// Elementwise square root.
template <Expression A>
UnaryExpr<detail::SqrtOp, A> sqrt(const A& a) {
  return {a};
}

}  // namespace arbor::ad
