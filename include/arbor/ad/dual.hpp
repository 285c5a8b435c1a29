// arbor: forward-mode automatic differentiation with a fixed number of directions.
//
// Dual<T, N> holds a value and N directional derivatives. It is an Eigen scalar, so every RBD
// template instantiates with it: seeding the inputs with unit directions gives the Jacobian of
// the algorithm along those directions (the paper's J^c, "AD through the RBD code"). Duals nest:
// Dual<Dual<double, N>, M> carries second derivatives (forward over forward), which is how the
// Hessians H^c and H^a are computed (see ad/rbd_functions.hpp).
//
// Storage is a plain array: sizeof(Dual<double, N>) = 8 (N + 1) bytes, no allocation.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <type_traits>

#include "arbor/core/math.hpp"

namespace arbor::ad {

template <class T, int N>
struct Dual;

namespace detail {
template <class X>
struct IsDual : std::false_type {};
template <class T, int N>
struct IsDual<Dual<T, N>> : std::true_type {};
}  // namespace detail

/// True for Dual<T, N> of any T, N.
template <class X>
inline constexpr bool is_dual_v = detail::IsDual<X>::value;

/// A plain arithmetic constant that mixes with a Dual without converting it first.
template <class A>
concept Arithmetic = std::is_arithmetic_v<A>;

/// Value and N directional derivatives of a scalar. `v` is the value, `d[k]` the derivative along
/// direction k. Arithmetic, comparisons (on the value only) and arbor::sin/cos/sqrt/sincos work
/// as for T; comparisons ignore the derivatives, so branching code is differentiated along the
/// branch taken.
template <class T, int N>
struct Dual {
  static_assert(N >= 1, "a Dual needs at least one direction");
  using Value = T;                      ///< type of the value and of each derivative
  static constexpr int directions = N;  ///< number of directions
  T v;                                  ///< value
  T d[N];                               ///< derivative along each direction

  /// Uninitialised, like a double (`Dual x;`); `Dual x{}` and `Dual()` are zero (value
  /// initialisation). Not zeroing by default keeps the expression layer's node values (arrays of
  /// duals that are written element by element) from being cleared first.
  constexpr Dual() = default;
  /// A constant (all derivatives zero).
  constexpr Dual(const T& x)
      : v(x), d{} {}  // NOLINT(google-explicit-constructor): scalar semantics
  /// A constant from a plain number (for nested duals: Dual<Dual<double, N>, M>(0.5)).
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) constexpr Dual(A x)
      : v(T(x)), d{} {}  // NOLINT(google-explicit-constructor)

  /// A variable: value x, derivative 1 along direction k and 0 along the others.
  static constexpr Dual variable(const T& x, int k) {
    Dual r(x);
    r.d[k] = T(1);
    return r;
  }

  // ---- compound assignment -------------------------------------------------------------------
  constexpr Dual& operator+=(const Dual& b) {
    v += b.v;
    for (int k = 0; k < N; ++k)
      d[k] += b.d[k];
    return *this;
  }
  constexpr Dual& operator-=(const Dual& b) {
    v -= b.v;
    for (int k = 0; k < N; ++k)
      d[k] -= b.d[k];
    return *this;
  }
  constexpr Dual& operator*=(const Dual& b) {
    for (int k = 0; k < N; ++k)
      d[k] = v * b.d[k] + d[k] * b.v;
    v *= b.v;
    return *this;
  }
  constexpr Dual& operator/=(const Dual& b) {
    const T inv = T(1) / b.v;
    v *= inv;
    for (int k = 0; k < N; ++k)
      d[k] = (d[k] - v * b.d[k]) * inv;
    return *this;
  }
  constexpr Dual& operator+=(const T& b) {
    v += b;
    return *this;
  }
  constexpr Dual& operator-=(const T& b) {
    v -= b;
    return *this;
  }
  constexpr Dual& operator*=(const T& b) {
    v *= b;
    for (int k = 0; k < N; ++k)
      d[k] *= b;
    return *this;
  }
  constexpr Dual& operator/=(const T& b) {
    const T inv = T(1) / b;
    return *this *= inv;
  }

  // ---- arithmetic (hidden friends: found only through a Dual argument) -----------------------
  friend constexpr Dual operator+(const Dual& a) { return a; }
  friend constexpr Dual operator-(const Dual& a) {
    Dual r;
    r.v = -a.v;
    for (int k = 0; k < N; ++k)
      r.d[k] = -a.d[k];
    return r;
  }
  friend constexpr Dual operator+(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v + b.v;
    for (int k = 0; k < N; ++k)
      r.d[k] = a.d[k] + b.d[k];
    return r;
  }
  friend constexpr Dual operator-(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v - b.v;
    for (int k = 0; k < N; ++k)
      r.d[k] = a.d[k] - b.d[k];
    return r;
  }
  friend constexpr Dual operator*(const Dual& a, const Dual& b) {
    Dual r;
    r.v = a.v * b.v;
    for (int k = 0; k < N; ++k)
      r.d[k] = a.v * b.d[k] + a.d[k] * b.v;
    return r;
  }
  friend constexpr Dual operator/(const Dual& a, const Dual& b) {
    Dual r;
    const T inv = T(1) / b.v;
    r.v = a.v * inv;
    for (int k = 0; k < N; ++k)
      r.d[k] = (a.d[k] - r.v * b.d[k]) * inv;
    return r;
  }
  // with the value type
  friend constexpr Dual operator+(const Dual& a, const T& b) {
    Dual r = a;
    r.v += b;
    return r;
  }
  friend constexpr Dual operator+(const T& a, const Dual& b) { return b + a; }
  friend constexpr Dual operator-(const Dual& a, const T& b) {
    Dual r = a;
    r.v -= b;
    return r;
  }
  friend constexpr Dual operator-(const T& a, const Dual& b) {
    Dual r;
    r.v = a - b.v;
    for (int k = 0; k < N; ++k)
      r.d[k] = -b.d[k];
    return r;
  }
  friend constexpr Dual operator*(const Dual& a, const T& b) {
    Dual r;
    r.v = a.v * b;
    for (int k = 0; k < N; ++k)
      r.d[k] = a.d[k] * b;
    return r;
  }
  friend constexpr Dual operator*(const T& a, const Dual& b) { return b * a; }
  friend constexpr Dual operator/(const Dual& a, const T& b) { return a * (T(1) / b); }
  friend constexpr Dual operator/(const T& a, const Dual& b) {
    Dual r;
    const T inv = T(1) / b.v;
    r.v = a * inv;
    const T m = -r.v * inv;
    for (int k = 0; k < N; ++k)
      r.d[k] = m * b.d[k];
    return r;
  }
  // with plain numbers, when T is itself a Dual (or another non-arithmetic type)
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) friend constexpr Dual operator+(const Dual& a, A b) {
    return a + T(b);
  }
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) friend constexpr Dual operator+(A a, const Dual& b) {
    return T(a) + b;
  }
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) friend constexpr Dual operator-(const Dual& a, A b) {
    return a - T(b);
  }
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) friend constexpr Dual operator-(A a, const Dual& b) {
    return T(a) - b;
  }
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) friend constexpr Dual operator*(const Dual& a, A b) {
    return a * T(b);
  }
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) friend constexpr Dual operator*(A a, const Dual& b) {
    return T(a) * b;
  }
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) friend constexpr Dual operator/(const Dual& a, A b) {
    return a / T(b);
  }
  template <Arithmetic A>
  requires(!std::is_same_v<A, T>) friend constexpr Dual operator/(A a, const Dual& b) {
    return T(a) / b;
  }

  // ---- known zero / known equal (core/math.hpp): value and every derivative --------------------
  /// a and all its derivatives are known to be zero (a skip of a multiplication by a drops its
  /// derivatives too, so a zero value alone is not enough).
  friend constexpr bool known_zero(const Dual& a) {
    if (!known_zero(a.v))
      return false;
    for (int i = 0; i < N; ++i)
      if (!known_zero(a.d[i]))
        return false;
    return true;
  }
  /// a and b are known to be equal in value and every derivative.
  friend constexpr bool known_equal(const Dual& a, const Dual& b) {
    if (!known_equal(a.v, b.v))
      return false;
    for (int i = 0; i < N; ++i)
      if (!known_equal(a.d[i], b.d[i]))
        return false;
    return true;
  }

  // ---- comparisons, on the value ---------------------------------------------------------------
  friend constexpr bool operator==(const Dual& a, const Dual& b) { return a.v == b.v; }
  friend constexpr bool operator<(const Dual& a, const Dual& b) { return a.v < b.v; }
  friend constexpr bool operator>(const Dual& a, const Dual& b) { return a.v > b.v; }
  friend constexpr bool operator<=(const Dual& a, const Dual& b) { return a.v <= b.v; }
  friend constexpr bool operator>=(const Dual& a, const Dual& b) { return a.v >= b.v; }

  // ---- elementary functions (found by ADL from arbor::sin/cos/sqrt/sincos) --------------------
  friend Dual sin(const Dual& a) {
    T s, c;
    arbor::sincos(a.v, s, c);
    Dual r(s);
    for (int k = 0; k < N; ++k)
      r.d[k] = c * a.d[k];
    return r;
  }
  friend Dual cos(const Dual& a) {
    T s, c;
    arbor::sincos(a.v, s, c);
    Dual r(c);
    const T ms = -s;
    for (int k = 0; k < N; ++k)
      r.d[k] = ms * a.d[k];
    return r;
  }
  friend void arbor_sincos(const Dual& a, Dual& s, Dual& c) {
    T sv, cv;
    arbor::sincos(a.v, sv, cv);
    s.v = sv;
    c.v = cv;
    const T ms = -sv;
    for (int k = 0; k < N; ++k) {
      s.d[k] = cv * a.d[k];
      c.d[k] = ms * a.d[k];
    }
  }
  friend Dual sqrt(const Dual& a) {
    Dual r(arbor::sqrt(a.v));
    const T h = T(0.5) / r.v;
    for (int k = 0; k < N; ++k)
      r.d[k] = h * a.d[k];
    return r;
  }
  /// |a| (derivative sign(a) d; at 0 the derivative of +a).
  friend Dual abs(const Dual& a) { return a.v < T(0) ? -a : a; }
};

/// The innermost plain value of a (possibly nested) dual, or the number itself.
template <class X>
constexpr auto value_of(const X& x) {
  if constexpr (is_dual_v<X>)
    return value_of(x.v);
  else
    return x;
}

}  // namespace arbor::ad

namespace Eigen {
/// Dual numbers are real scalars to Eigen (no vectorisation, initialisation required).
template <class T, int N>
struct NumTraits<arbor::ad::Dual<T, N>> : NumTraits<T> {
  using Real = arbor::ad::Dual<T, N>;
  using NonInteger = arbor::ad::Dual<T, N>;
  using Nested = arbor::ad::Dual<T, N>;
  using Literal = arbor::ad::Dual<T, N>;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = (N + 1) * int(NumTraits<T>::ReadCost),
    AddCost = (N + 1) * int(NumTraits<T>::AddCost),
    MulCost = (2 * N + 1) * int(NumTraits<T>::MulCost)
  };
  static inline Real epsilon() { return Real(NumTraits<T>::epsilon()); }
  static inline Real dummy_precision() { return Real(NumTraits<T>::dummy_precision()); }
  static inline Real highest() { return Real(NumTraits<T>::highest()); }
  static inline Real lowest() { return Real(NumTraits<T>::lowest()); }
  static inline int digits10() { return NumTraits<T>::digits10(); }
};
}  // namespace Eigen
