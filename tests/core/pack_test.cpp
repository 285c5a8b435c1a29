// arbor::Pack<T, L> (core/pack.hpp), the lane type of the batched generated stage code, against
// plain scalar arithmetic lane by lane, for double and float at 1, 2, 4 and 8 lanes: + - * / and
// negation bit for bit (signed zeros, infinities, NaN, subnormals included); sqrt, sin, cos,
// sincos, positive_part and unit_step equal to arbor's scalar customisation points; the limits;
// a straight-line function (the shape of generated code: constants, products, sums, a quotient,
// sqrt, sin and cos) evaluated once at a pack and once per lane at the scalar, within a few units
// of round-off. Built with -ffp-contract=off (tests/core/CMakeLists.txt): the compiler would
// otherwise contract a * b + c into fused multiply-adds differently in the lanes and in the
// scalar calls (inside sincos, on the Cortex-M7 and AArch64 at -O3), and bit for bit is the
// property under test. Built at the ISA variants too (the packs are SIMD registers there) and on
// the cross targets.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "arbor/core/pack.hpp"
#include "arbor_test.hpp"
#include "isa.hpp"

namespace {

using arbor::Pack;

/// a and b the same bits, or both NaN.
template <class T>
bool same(T a, T b) {
  if (std::isnan(a) || std::isnan(b))
    return std::isnan(a) && std::isnan(b);
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

/// Values of every kind: random of several magnitudes, signed zeros, infinities, NaN, subnormal.
template <class T>
T value(std::mt19937& rng, int i) {
  constexpr T inf = std::numeric_limits<T>::infinity();
  const T specials[] = {T(0),
                        -T(0),
                        inf,
                        -inf,
                        std::numeric_limits<T>::quiet_NaN(),
                        std::numeric_limits<T>::denorm_min() * 3,
                        T(1),
                        T(-2.5)};
  if (i % 5 == 4)
    return specials[rng() % 8];
  std::uniform_real_distribution<T> u(T(-2), T(2));
  std::uniform_int_distribution<int> e(-20, 20);
  return std::ldexp(u(rng), e(rng));
}

template <class T, int L>
Pack<T, L> random_pack(std::mt19937& rng, int& i) {
  Pack<T, L> p;
  for (int l = 0; l < L; ++l)
    p.set(l, value<T>(rng, i++));
  return p;
}

/// The shape of generated stage code (see gen/ad): constants, a chain of products and sums, a
/// quotient, sqrt, sin, cos and positive_part, one scalar type S throughout.
template <class S>
S straight_line(const S& x, const S& y, const S& z) {
  using arbor::cos;
  using arbor::positive_part;
  using arbor::sin;
  using arbor::sqrt;
  const S t0 = S(0.75) * x + S(-1.25) * y;
  const S t1 = sin(t0) * cos(y) - S(0.5) * z;
  const S t2 = sqrt(x * x + y * y + S(1));
  const S t3 = t1 / t2 + positive_part(z - x);
  const S t4 = -t3 * t0 + cos(t2) * sin(t1);
  return t4 * t4 + t3;
}

template <class T, int L>
void check_lanes(unsigned seed) {
  using P = Pack<T, L>;
  static_assert(P::lanes == L && sizeof(P) == sizeof(T) * L);
  std::mt19937 rng(seed);
  int count = 0;
  long mismatches = 0;
  for (int rep = 0; rep < 200; ++rep) {
    const P a = random_pack<T, L>(rng, count), b = random_pack<T, L>(rng, count);
    P sum, diff, prod, quot, neg, pos, sq, s, c, pp, st, ss, cc;
    {
      arbor::test::NoAllocScope guard;  // (the operations only: a failed check below allocates)
      sum = a + b;
      diff = a - b;
      prod = a * b;
      quot = a / b;
      neg = -a;
      pos = +a;
      sq = sqrt(a);
      s = sin(a);
      c = cos(a);
      pp = positive_part(a);
      st = unit_step(a);
      arbor::sincos(a, ss, cc);
    }
    for (int l = 0; l < L; ++l) {
      const T x = a[l], y = b[l];
      T sl, cl;
      arbor::sincos(x, sl, cl);
      const bool ok[] = {same(sum[l], T(x + y)),
                         same(diff[l], T(x - y)),
                         same(prod[l], T(x * y)),
                         same(quot[l], T(x / y)),
                         same(neg[l], T(-x)),
                         same(pos[l], x),
                         same(sq[l], arbor::sqrt(x)),
                         same(s[l], arbor::sin(x)),
                         same(c[l], arbor::cos(x)),
                         same(ss[l], sl) && same(cc[l], cl),
                         same(pp[l], arbor::positive_part(x)),
                         same(st[l], arbor::unit_step(x))};
      for (int k = 0; k < int(sizeof(ok)); ++k) {
        EXPECT_TRUE(ok[k]) << "operation " << k << ", lane " << l << " of " << L << ": x = " << x
                           << ", y = " << y;
        mismatches += !ok[k];
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  // the select operations on the values that decide them
  P e(T(0));
  e.set(0, -T(0));
  if (L > 1)
    e.set(1, std::numeric_limits<T>::quiet_NaN());
  const P pe = positive_part(e), ue = unit_step(e);
  for (int l = 0; l < L; ++l) {
    EXPECT_EQ(pe[l], T(0));
    EXPECT_FALSE(std::signbit(pe[l])) << l;  // max(-0, 0) and max(NaN, 0) are +0, as the scalar's
    EXPECT_EQ(ue[l], T(0));
  }
  // the limits, lane by lane
  using Lim = std::numeric_limits<P>;
  static_assert(Lim::is_specialized && Lim::has_infinity &&
                Lim::digits == std::numeric_limits<T>::digits);
  for (int l = 0; l < L; ++l) {
    EXPECT_EQ(Lim::infinity()[l], std::numeric_limits<T>::infinity());
    EXPECT_EQ((-Lim::infinity())[l], -std::numeric_limits<T>::infinity());
    EXPECT_TRUE(std::isnan(Lim::quiet_NaN()[l]));
    EXPECT_EQ(Lim::lowest()[l], std::numeric_limits<T>::lowest());
    EXPECT_EQ(Lim::epsilon()[l], std::numeric_limits<T>::epsilon());
  }
  // straight-line code at the pack against the same code per lane at the scalar
  std::uniform_real_distribution<T> u(T(-3), T(3));
  double worst = 0;
  for (int rep = 0; rep < 200; ++rep) {
    P x, y, z;
    for (int l = 0; l < L; ++l) {
      x.set(l, u(rng));
      y.set(l, u(rng));
      z.set(l, u(rng));
    }
    const P f = straight_line(x, y, z);
    for (int l = 0; l < L; ++l) {
      const T r = straight_line(x[l], y[l], z[l]);
      const double d = std::abs(double(f[l]) - double(r)) / (1 + std::abs(double(r)));
      worst = std::max(worst, d);
    }
  }
  EXPECT_LE(worst, 64 * double(std::numeric_limits<T>::epsilon())) << L;
}

TEST(Pack, LanesAreTheScalarsArithmetic) {
  arbor::test::print_isa();
  check_lanes<double, 1>(1);
  check_lanes<double, 2>(2);
  check_lanes<double, 4>(3);
  check_lanes<double, 8>(4);
  check_lanes<float, 1>(5);
  check_lanes<float, 2>(6);
  check_lanes<float, 4>(7);
  check_lanes<float, 8>(8);
}

// pack_lanes: one SIMD register of the target (the batched stage code's width), 1 without SIMD.
TEST(Pack, LanesFillOneRegisterOfTheTarget) {
#if defined(__AVX__)
  EXPECT_EQ(arbor::simd_bytes, 32);
#elif defined(__SSE2__) || defined(__ARM_NEON)
  EXPECT_EQ(arbor::simd_bytes, 16);
#else
  EXPECT_EQ(arbor::simd_bytes, 0);
#endif
  if (arbor::simd_bytes > 0) {
    EXPECT_EQ(arbor::pack_lanes<double> * 8, arbor::simd_bytes);
    EXPECT_EQ(arbor::pack_lanes<float> * 4, arbor::simd_bytes);
  } else {
    EXPECT_EQ(arbor::pack_lanes<double>, 1);
    EXPECT_EQ(arbor::pack_lanes<float>, 1);
  }
}

}  // namespace
