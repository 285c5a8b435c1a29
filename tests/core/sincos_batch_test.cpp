// detail::sincos_double_batch (core/sincos_batch.hpp: the joints' sines and cosines in one
// branch-free loop over SIMD lanes) against detail::sincos_double (core/math.hpp, itself tested
// against glibc in tests/core/math_test.cpp), bit for bit: random arguments over the joints'
// range and beyond, arguments next to multiples of pi/2, and the arguments the batch hands back to
// sincos_double one by one (|x| > 1e5, |x| < 2^-26, signed zeros, infinities, NaN), alone and
// mixed into batches of ordinary ones, for batch sizes 1 to 9.
#include <gtest/gtest.h>

#include <arbor/core/sincos_batch.hpp>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "alloc_guard.hpp"

namespace {

using arbor::test::NoAllocScope;

/// Checks one batch of N arguments starting at x against sincos_double, bit for bit.
template <int N>
int mismatches(const double* x) {
  double s[N], c[N];
  {
    NoAllocScope guard;
    arbor::detail::sincos_double_batch<N>(x, s, c);
  }
  int bad = 0;
  for (int j = 0; j < N; ++j) {
    double s1, c1;
    arbor::detail::sincos_double(x[j], s1, c1);
    const bool same = std::bit_cast<std::uint64_t>(s[j]) == std::bit_cast<std::uint64_t>(s1) &&
                      std::bit_cast<std::uint64_t>(c[j]) == std::bit_cast<std::uint64_t>(c1);
    if (!same) {
      ADD_FAILURE() << "N = " << N << ", lane " << j << ", x = " << x[j] << ": batch (" << s[j]
                    << ", " << c[j] << "), sincos_double (" << s1 << ", " << c1 << ")";
      ++bad;
    }
  }
  return bad;
}

/// Every batch size 1..9 over consecutive windows of xs.
int all_sizes(const std::vector<double>& xs) {
  int bad = 0;
  auto run = [&]<int N>() {
    for (std::size_t i = 0; i + N <= xs.size(); i += N)
      bad += mismatches<N>(xs.data() + i);
  };
  run.template operator()<1>();
  run.template operator()<2>();
  run.template operator()<3>();
  run.template operator()<4>();
  run.template operator()<5>();
  run.template operator()<7>();
  run.template operator()<8>();
  run.template operator()<9>();
  return bad;
}

TEST(SincosBatch, RandomArgumentsBitForBit) {
  std::mt19937_64 rng(20261204);
  std::uniform_real_distribution<double> joint(-4 * M_PI, 4 * M_PI), wide(-1e5, 1e5);
  std::vector<double> xs;
  for (int i = 0; i < 20000; ++i)
    xs.push_back(joint(rng));
  for (int i = 0; i < 5000; ++i)
    xs.push_back(wide(rng));
  // next to the multiples of pi/2, where the reduction cancels
  for (int k = -40; k <= 40; ++k) {
    const double m = k * (M_PI / 2);
    xs.push_back(m);
    xs.push_back(std::nextafter(m, INFINITY));
    xs.push_back(std::nextafter(m, -INFINITY));
  }
  EXPECT_EQ(all_sizes(xs), 0);
}

TEST(SincosBatch, ArgumentsHandedBackBitForBit) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double special[] = {0.0, -0.0, 0x1p-27,     -0x1p-27, 0x1p-26, -0x1p-26, 1e-300, 5e-324,
                            1e5, -1e5, 1.0000001e5, -2e5,     1e300,   inf,      -inf,   nan};
  std::vector<double> xs;
  for (double v : special) {
    xs.push_back(v);
    xs.push_back(0.3);  // ordinary lanes around each special one
    xs.push_back(-1.7);
  }
  for (double v : special)  // and specials next to each other
    xs.push_back(v);
  EXPECT_EQ(all_sizes(xs), 0);
}

}  // namespace
