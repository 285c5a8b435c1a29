// arbor: scalar helpers of the expression layer for (nested) duals: the innermost scalar type,
// constants and arguments lifted or seeded into Dual<...<T>...>, and arithmetic with a constant
// of the innermost type that touches each component once (x * c is one multiplication per
// component, not a dual product). Cost: at most one operation per component of the dual.
#pragma once

#include <type_traits>

#include "arbor/ad/dual.hpp"

namespace arbor::ad::detail {

/// The innermost scalar of a (possibly nested) dual.
template <class S>
struct BaseScalar {
  using type = S;
};
template <class T, int N>
struct BaseScalar<Dual<T, N>> {
  using type = typename BaseScalar<T>::type;
};
template <class S>
using base_t = typename BaseScalar<S>::type;

/// S from a value of its innermost scalar type (all derivatives zero).
template <class S, class B>
S lift_constant(const B& c) {
  if constexpr (is_dual_v<S>)
    return S(lift_constant<typename S::Value>(c));
  else
    return S(c);
}

/// S (T nested in duals) from an argument value of type T: a constant (zero derivatives).
template <class S, class T>
S lift_argument(const T& x) {
  if constexpr (std::is_same_v<S, T>)
    return x;
  else
    return S(lift_argument<typename S::Value, T>(x));
}

/// S (T nested in duals) from an argument value of type T, seeded along direction k at every
/// dual level above T.
template <class S, class T>
S seed_argument(const T& x, int k) {
  if constexpr (std::is_same_v<S, T>)
    return x;
  else
    return S::variable(seed_argument<typename S::Value, T>(x, k), k);
}

/// x * c for a constant c of the innermost scalar type (every component scaled once).
template <class S, class B>
S scale(const S& x, const B& c) {
  if constexpr (is_dual_v<S>) {
    S r;
    r.v = scale(x.v, c);
    for (int k = 0; k < S::directions; ++k)
      r.d[k] = scale(x.d[k], c);
    return r;
  } else {
    return S(x * c);
  }
}

/// out = a + x * c for a constant c of the innermost scalar type, written in place component by
/// component (no temporary; out may be a or x): the same operations, and so the same result, as
/// a + scale(x, c).
template <class S, class B>
void add_scaled_to(S& out, const S& a, const S& x, const B& c) {
  if constexpr (is_dual_v<S>) {
    add_scaled_to(out.v, a.v, x.v, c);
    for (int k = 0; k < S::directions; ++k)
      add_scaled_to(out.d[k], a.d[k], x.d[k], c);
  } else {
    out = a + x * c;
  }
}

/// out = a + (x + y) * c for a constant c of the innermost scalar type, in place as
/// add_scaled_to (the same result as a + scale(x + y, c)).
template <class S, class B>
void add_sum_scaled_to(S& out, const S& a, const S& x, const S& y, const B& c) {
  if constexpr (is_dual_v<S>) {
    add_sum_scaled_to(out.v, a.v, x.v, y.v, c);
    for (int k = 0; k < S::directions; ++k)
      add_sum_scaled_to(out.d[k], a.d[k], x.d[k], y.d[k], c);
  } else {
    out = a + (x + y) * c;
  }
}

/// x / c for a constant c of the innermost scalar type.
template <class S, class B>
S divide(const S& x, const B& c) {
  if constexpr (is_dual_v<S>) {
    S r;
    r.v = divide(x.v, c);
    for (int k = 0; k < S::directions; ++k)
      r.d[k] = divide(x.d[k], c);
    return r;
  } else {
    return S(x / c);
  }
}

/// x + c for a constant c (only the innermost value changes).
template <class S, class B>
S shift(const S& x, const B& c) {
  if constexpr (is_dual_v<S>) {
    S r = x;
    r.v = shift(x.v, c);
    return r;
  } else {
    return S(x + c);
  }
}

/// c - x for a constant c.
template <class S, class B>
S rsub(const B& c, const S& x) {
  if constexpr (is_dual_v<S>) {
    S r;
    r.v = rsub(c, x.v);
    for (int k = 0; k < S::directions; ++k)
      r.d[k] = -x.d[k];
    return r;
  } else {
    return S(c - x);
  }
}

/// c / x for a constant c.
template <class S, class B>
S rdiv(const B& c, const S& x) {
  if constexpr (is_dual_v<S>)
    return lift_constant<typename S::Value>(c) / x;
  else
    return S(c / x);
}

}  // namespace arbor::ad::detail
