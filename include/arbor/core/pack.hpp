// arbor: Pack<T, L>, L lanes of a floating type computed together: a scalar type for
// straight-line code that runs the same arithmetic at L points at once (the generated stage code
// of ocp/generated_stage.hpp over L stages of a horizon). Built on the GCC / Clang vector
// extension: + - * / and negation are one SIMD instruction per register where the target has
// SIMD (elsewhere the compiler lowers them lane by lane), sqrt, sin, cos through the scalar's own
// customisation points lane by lane (sincos of double lanes in one batch, core/sincos_batch.hpp),
// positive_part and unit_step by masked bits (no branch). Lane l of the result of an
// operation is the operation on lane l of its operands: IEEE arithmetic per lane, so Pack code
// gives the scalar code's values bit for bit where the compiler does not contract a * b + c into
// fused multiply-adds (-ffp-contract=off); where it does (FMA targets at -O2 and above), it may
// contract vector and scalar code differently: the same values to round-off.
// Sizes: L a power of two; the pack is aligned to its size (32 B for 4 doubles); no heap.
// pack_lanes<T>: the lanes of T in one register of simd_bytes (core/config.hpp; 1 without SIMD).
#pragma once

#include <limits>
#include <type_traits>

#include "arbor/core/math.hpp"
#include "arbor/core/sincos_batch.hpp"

namespace arbor {

/// Lanes of T in one SIMD register of the target (1 without SIMD or for a wider T).
template <class T>
inline constexpr int pack_lanes = simd_bytes >= 2 * int(sizeof(T)) ? simd_bytes / int(sizeof(T))
                                                                   : 1;

/// L lanes of floating type T (see the top of this file).
template <class T, int L>
struct Pack {
  static_assert(std::is_floating_point_v<T>, "Pack holds float or double lanes");
  static_assert(L >= 1 && (L & (L - 1)) == 0, "the lane count is a power of two");
  static constexpr int lanes = L;
  using Lanes [[gnu::vector_size(sizeof(T) * L)]] = T;

  Lanes v;  ///< the lanes (v[l]: lane l)
  /// The comparison's result: per lane all bits set (true) or none, an integer of T's size.
  using Mask = decltype(Lanes{} > T(0));

  Pack() = default;
  /// Every lane x (the generated code's constants: S(0.5)).
  template <class U>
  requires std::is_arithmetic_v<U>
  explicit Pack(U x) {
    for (int l = 0; l < L; ++l)
      v[l] = T(x);
  }
  T operator[](int l) const { return v[l]; }
  void set(int l, T x) { v[l] = x; }

  friend Pack operator+(const Pack& a, const Pack& b) { return of(a.v + b.v); }
  friend Pack operator-(const Pack& a, const Pack& b) { return of(a.v - b.v); }
  friend Pack operator*(const Pack& a, const Pack& b) { return of(a.v * b.v); }
  friend Pack operator/(const Pack& a, const Pack& b) { return of(a.v / b.v); }
  friend Pack operator-(const Pack& a) { return of(-a.v); }
  friend Pack operator+(const Pack& a) { return a; }

  // the customisation points of core/math.hpp, found by argument-dependent lookup
  friend Pack sqrt(const Pack& a) {
    Pack r;
    for (int l = 0; l < L; ++l)
      r.v[l] = arbor::sqrt(a.v[l]);
    return r;
  }
  friend Pack sin(const Pack& a) {
    Pack r;
    for (int l = 0; l < L; ++l)
      r.v[l] = arbor::sin(a.v[l]);
    return r;
  }
  friend Pack cos(const Pack& a) {
    Pack r;
    for (int l = 0; l < L; ++l)
      r.v[l] = arbor::cos(a.v[l]);
    return r;
  }
  /// arbor::sincos's customisation: double lanes in one batch (core/sincos_batch.hpp:
  /// sincos_double's values, across SIMD lanes), float lane by lane.
  friend void arbor_sincos(const Pack& a, Pack& s, Pack& c) {
    T x[L], sl[L], cl[L];
    for (int l = 0; l < L; ++l)
      x[l] = a.v[l];
    if constexpr (std::is_same_v<T, double>) {
      detail::sincos_double_batch<L>(x, sl, cl);
    } else {
      for (int l = 0; l < L; ++l)
        arbor::sincos(x[l], sl[l], cl[l]);
    }
    for (int l = 0; l < L; ++l) {
      s.v[l] = sl[l];
      c.v[l] = cl[l];
    }
  }
  /// max(a, 0) per lane as the scalar's a > 0 ? a : 0: +0 for a NaN lane and for -0. The lanes'
  /// bits masked by the comparison (__builtin_bit_cast: no function returns a vector, so no ABI
  /// note on targets narrower than the pack), then + 0: Clang for AArch64 turns the mask (as a
  /// select) into a maximum, which may keep -0; -0 + 0 is +0 (core_pack_test).
  friend Pack positive_part(const Pack& a) {
    return of(__builtin_bit_cast(Lanes, __builtin_bit_cast(Mask, a.v) & (a.v > T(0))) + Lanes{});
  }
  /// 1 where a lane is > 0, else +0 (the bits of 1 masked by the comparison).
  friend Pack unit_step(const Pack& a) {
    return of(__builtin_bit_cast(Lanes, __builtin_bit_cast(Mask, Lanes{} + T(1)) & (a.v > T(0))));
  }

 private:
  static Pack of(const Lanes& x) {
    Pack r;
    r.v = x;
    return r;
  }
};

}  // namespace arbor

/// The limits of a pack: every lane T's (generated code writes infinite row bounds as
/// std::numeric_limits<S>::infinity()).
template <class T, int L>
class std::numeric_limits<arbor::Pack<T, L>> {
  using P = arbor::Pack<T, L>;
  using N = std::numeric_limits<T>;

 public:
  static constexpr bool is_specialized = true;
  static constexpr bool has_infinity = N::has_infinity;
  static constexpr bool has_quiet_NaN = N::has_quiet_NaN;
  static constexpr int digits = N::digits;
  static P infinity() { return P(N::infinity()); }
  static P quiet_NaN() { return P(N::quiet_NaN()); }
  static P epsilon() { return P(N::epsilon()); }
  static P min() { return P(N::min()); }
  static P max() { return P(N::max()); }
  static P lowest() { return P(N::lowest()); }
};
