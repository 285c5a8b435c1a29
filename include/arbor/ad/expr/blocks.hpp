// arbor: parts and stacks of expressions: segment<Start, Len>(a), element<I>(a), cat(a, b, ...)
// (vertical concatenation). Cost: copies of the selected or stacked elements, no arithmetic (a
// segment stacked by cat is copied once, from its operand).
#pragma once

#include <tuple>
#include <type_traits>

#include "arbor/ad/expr/values.hpp"

namespace arbor::ad {

/// Elements Start .. Start + Len - 1 of an expression.
template <int Start, int Len, Expression A>
struct SegmentExpr {
  static_assert(Start >= 0 && Len >= 1 && Start + Len <= A::rows, "segment out of range");
  using expression_tag = void;                 ///< marks an expression node
  static constexpr int rows = Len;             ///< size
  static constexpr int segment_start = Start;  ///< first element taken
  A arg;                                       ///< operand
  /// The segment.
  template <class Env>
  Values<typename Env::Scalar, Len> eval(const Env& env) const {
    const auto& a = arg.eval(env);
    Values<typename Env::Scalar, Len> r;
    for (int i = 0; i < Len; ++i)
      r[i] = a[Start + i];
    return r;
  }
};

/// Concatenation of expressions (stacked vertically).
template <Expression... A>
struct CatExpr {
  static_assert(sizeof...(A) >= 1, "cat needs at least one operand");
  using expression_tag = void;                  ///< marks an expression node
  static constexpr int rows = (A::rows + ...);  ///< size
  std::tuple<A...> parts;                       ///< operands
  /// The stacked values.
  template <class Env>
  Values<typename Env::Scalar, rows> eval(const Env& env) const {
    Values<typename Env::Scalar, rows> r;
    int off = 0;
    auto put = [&](const auto& p) {
      using P = std::remove_cvref_t<decltype(p)>;
      if constexpr (requires { P::segment_start; }) {  // a segment: straight from its operand
        const auto& v = p.arg.eval(env);               // (a symbol's is a reference: one copy)
        for (int i = 0; i < P::rows; ++i)
          r[off + i] = v[P::segment_start + i];
      } else {
        const auto& v = p.eval(env);
        for (int i = 0; i < P::rows; ++i)
          r[off + i] = v[i];
      }
      off += P::rows;
    };
    std::apply([&](const auto&... p) { (put(p), ...); }, parts);
    return r;
  }
};

/// Elements Start .. Start + Len - 1.
template <int Start, int Len, Expression A>
SegmentExpr<Start, Len, A> segment(const A& a) {
  return {a};
}
/// Element I (1 row).
template <int I, Expression A>
SegmentExpr<I, 1, A> element(const A& a) {
  return {a};
}
/// Vertical concatenation (a single operand is returned as is).
template <Expression... A>
auto cat(const A&... a) {
  if constexpr (sizeof...(A) == 1)
    return (a, ...);
  else
    return CatExpr<A...>{std::tuple<A...>(a...)};
}

}  // namespace arbor::ad
