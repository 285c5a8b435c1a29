// arbor::sincos for double (core/math.hpp, detail::sincos_double: Cody-Waite reduction and Taylor
// polynomials, no library call) against glibc's sin and cos, in units in the last place of the
// library's result: random arguments over the fast path's range |x| <= 1e5 (uniform and
// log-uniform), arguments next to multiples of pi/2 (where the reduction cancels), signed zeros,
// the fallback beyond 1e5 and non-finite input; arbor::sin and arbor::cos alone equal to it; and
// sin^2 + cos^2 = 1.
#include <gtest/gtest.h>

#include <arbor/core/math.hpp>
#include <cmath>
#include <limits>
#include <random>

#include "alloc_guard.hpp"

namespace {

using arbor::test::NoAllocScope;

/// |a - b| in units of the spacing of doubles at b (at least the smallest normal's spacing).
double ulps(double a, double b) {
  const double b_abs = std::max(std::abs(b), std::numeric_limits<double>::min());
  const double spacing = std::nextafter(b_abs, INFINITY) - b_abs;
  return std::abs(a - b) / spacing;
}

struct Worst {
  double s = 0, c = 0, xs = 0, xc = 0;
  void check(double x) {
    double s_ours, c_ours;
    arbor::sincos(x, s_ours, c_ours);
    const double es = ulps(s_ours, std::sin(x)), ec = ulps(c_ours, std::cos(x));
    if (es > s) {
      s = es;
      xs = x;
    }
    if (ec > c) {
      c = ec;
      xc = x;
    }
  }
};

TEST(Sincos, WithinOneUlpOfTheLibraryOnRandomArguments) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> wide(-1e5, 1e5), joint(-10.0, 10.0), expo(-30.0, 5.0);
  Worst w;
  for (int i = 0; i < 300000; ++i) {
    w.check(wide(rng));
    w.check(joint(rng));
    const double x = std::pow(10.0, expo(rng));
    w.check(x);
    w.check(-x);
  }
  EXPECT_LE(w.s, 1.0) << "sin at x = " << w.xs;
  EXPECT_LE(w.c, 1.0) << "cos at x = " << w.xc;
}

TEST(Sincos, NextToMultiplesOfHalfPiTheReductionKeepsItsAccuracy) {
  // the doubles nearest to k pi/2 and their neighbours: sin or cos is tiny there, so an error of
  // the reduction shows up as many ulps of the result
  Worst w;
  const double half_pi = 1.5707963267948966;
  for (int k = -63000; k <= 63000; k += 7) {
    double x = k * half_pi;
    for (int step = 0; step < 3; ++step) {
      w.check(x);
      x = std::nextafter(x, INFINITY);
    }
  }
  EXPECT_LE(w.s, 1.0) << "sin at x = " << w.xs;
  EXPECT_LE(w.c, 1.0) << "cos at x = " << w.xc;
}

TEST(Sincos, SignedZerosBoundaryFallbackAndNonFinite) {
  double s, c;
  arbor::sincos(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_FALSE(std::signbit(s));
  EXPECT_EQ(c, 1.0);
  arbor::sincos(-0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_TRUE(std::signbit(s));
  EXPECT_EQ(c, 1.0);
  for (double x : {1e5, -1e5, std::nextafter(1e5, INFINITY), 3e7, -1e300}) {
    arbor::sincos(x, s, c);
    EXPECT_LE(ulps(s, std::sin(x)), 1.0) << x;
    EXPECT_LE(ulps(c, std::cos(x)), 1.0) << x;
  }
  for (double x : {std::nextafter(1e5, INFINITY), 3e7}) {  // the library itself beyond 1e5
    arbor::sincos(x, s, c);
    EXPECT_EQ(s, std::sin(x));
    EXPECT_EQ(c, std::cos(x));
  }
  for (double x : {std::numeric_limits<double>::quiet_NaN(), double(INFINITY), -double(INFINITY)}) {
    arbor::sincos(x, s, c);
    EXPECT_TRUE(std::isnan(s)) << x;
    EXPECT_TRUE(std::isnan(c)) << x;
  }
}

TEST(Sincos, SinAndCosAloneGiveTheSameValues) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> d(-2e5, 2e5);
  for (int i = 0; i < 10000; ++i) {
    const double x = d(rng);
    double s, c;
    arbor::sincos(x, s, c);
    EXPECT_EQ(arbor::sin(x), s) << x;
    EXPECT_EQ(arbor::cos(x), c) << x;
  }
}

TEST(Sincos, PythagorasAndNoAllocation) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> d(-100.0, 100.0);
  NoAllocScope guard;
  double worst = 0;
  for (int i = 0; i < 100000; ++i) {
    double s, c;
    arbor::sincos(d(rng), s, c);
    worst = std::max(worst, std::abs(s * s + c * c - 1.0));
  }
  EXPECT_LE(worst, 4 * std::numeric_limits<double>::epsilon());
}

}  // namespace
