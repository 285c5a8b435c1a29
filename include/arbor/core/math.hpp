// arbor: scalar customisation points. Every algorithm calls arbor::sin/cos/sqrt, never std::
// directly, so that AD and operation-counting scalar types plug in by overloading these names in
// their own namespace (found by argument-dependent lookup) or in namespace arbor.
#pragma once

#include <cmath>
#include <type_traits>

namespace arbor {

namespace math_detail {
using std::cos;
using std::sin;
using std::sqrt;
template <class T>
inline auto adl_sin(const T& x) -> decltype(sin(x)) {
  return sin(x);
}
template <class T>
inline auto adl_cos(const T& x) -> decltype(cos(x)) {
  return cos(x);
}
template <class T>
inline auto adl_sqrt(const T& x) -> decltype(sqrt(x)) {
  return sqrt(x);
}
}  // namespace math_detail

/// Sine; built-in floating types use std::sin, others the overload found by ADL.
template <class T>
inline T sin(const T& x) {
  return T(math_detail::adl_sin(x));
}
/// Cosine; built-in floating types use std::cos, others the overload found by ADL.
template <class T>
inline T cos(const T& x) {
  return T(math_detail::adl_cos(x));
}
/// Square root; built-in floating types use std::sqrt, others the overload found by ADL.
template <class T>
inline T sqrt(const T& x) {
  return T(math_detail::adl_sqrt(x));
}

/// Sine and cosine of the same angle (one call site, so a scalar type may share work). A scalar
/// type that can compute both at once provides `arbor_sincos(x, s, c)`, found by ADL.
template <class T>
inline void sincos(const T& x, T& s, T& c) {
  if constexpr (requires { arbor_sincos(x, s, c); }) {
    arbor_sincos(x, s, c);
  } else {
    s = arbor::sin(x);
    c = arbor::cos(x);
  }
}

}  // namespace arbor
