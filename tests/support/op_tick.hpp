// arbor (measurement instrument, not part of the library): a scalar that counts every arithmetic
// operation it executes, with no folding: a multiplication by a structural zero costs one
// operation like any other, so dense execution of derivatives shows (Counted, op_count.hpp,
// folds such operations away the way a symbolic tool would, and counts what remains).
//
// One global tally (tick_count()), for single-threaded measurement in tests and benchmarks,
// which is why this lives in tests/support and not in include/arbor.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

namespace arbor::ad {

namespace detail {
inline std::uint64_t tick_tally = 0;
}  // namespace detail

/// The number of operations executed on Tick values since the last reset_tick_count().
inline std::uint64_t tick_count() {
  return detail::tick_tally;
}
/// Sets the tally to zero.
inline void reset_tick_count() {
  detail::tick_tally = 0;
}

/// A double that counts each +, -, *, /, negation, sin, cos and sqrt as one operation.
struct Tick {
  double x = 0;  ///< the value
  Tick() = default;
  Tick(double v) : x(v) {}  // NOLINT(google-explicit-constructor): scalar semantics
  friend Tick operator+(Tick a, Tick b) { return ++detail::tick_tally, Tick(a.x + b.x); }
  friend Tick operator-(Tick a, Tick b) { return ++detail::tick_tally, Tick(a.x - b.x); }
  friend Tick operator*(Tick a, Tick b) { return ++detail::tick_tally, Tick(a.x * b.x); }
  friend Tick operator/(Tick a, Tick b) { return ++detail::tick_tally, Tick(a.x / b.x); }
  friend Tick operator-(Tick a) { return ++detail::tick_tally, Tick(-a.x); }
  friend Tick operator+(Tick a) { return a; }
  Tick& operator+=(Tick b) { return *this = *this + b; }
  Tick& operator-=(Tick b) { return *this = *this - b; }
  Tick& operator*=(Tick b) { return *this = *this * b; }
  Tick& operator/=(Tick b) { return *this = *this / b; }
  friend Tick sin(Tick a) { return ++detail::tick_tally, Tick(std::sin(a.x)); }
  friend Tick cos(Tick a) { return ++detail::tick_tally, Tick(std::cos(a.x)); }
  friend Tick sqrt(Tick a) { return ++detail::tick_tally, Tick(std::sqrt(a.x)); }
  friend bool operator<(Tick a, Tick b) { return a.x < b.x; }
  friend bool operator>(Tick a, Tick b) { return a.x > b.x; }
  friend bool operator<=(Tick a, Tick b) { return a.x <= b.x; }
  friend bool operator>=(Tick a, Tick b) { return a.x >= b.x; }
  friend bool operator==(Tick a, Tick b) { return a.x == b.x; }
  friend bool operator!=(Tick a, Tick b) { return a.x != b.x; }
};

}  // namespace arbor::ad

namespace Eigen {
template <>
struct NumTraits<arbor::ad::Tick> : NumTraits<double> {
  using Real = arbor::ad::Tick;
  using NonInteger = arbor::ad::Tick;
  using Nested = arbor::ad::Tick;
  using Literal = arbor::ad::Tick;
};
}  // namespace Eigen
