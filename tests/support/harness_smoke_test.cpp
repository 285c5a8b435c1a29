// The test harness on every target: checks that hold pass, and the arithmetic the library relies
// on works (FPU enabled, double and float, libm).
#include <cmath>
#include <cstdint>

#include "arbor_test.hpp"

namespace {

volatile double g_x = 0.5;  // volatile: computed at run time, not folded by the compiler
volatile float g_xf = 0.5f;

TEST(HarnessSmoke, IntegerAndBooleanChecks) {
  EXPECT_EQ(2 + 2, 4);
  EXPECT_NE(1, 2);
  EXPECT_LT(1, 2);
  EXPECT_LE(2, 2);
  EXPECT_GT(3, 2);
  EXPECT_GE(3, 3);
  EXPECT_TRUE(sizeof(std::uint32_t) == 4);
  EXPECT_FALSE(1 > 2);
}

TEST(HarnessSmoke, DoubleArithmeticAndLibm) {
  const double x = g_x;
  EXPECT_NEAR(std::sin(x) * std::sin(x) + std::cos(x) * std::cos(x), 1.0, 1e-15);
  EXPECT_NEAR(std::sqrt(x) * std::sqrt(x), x, 1e-15);
  EXPECT_DOUBLE_EQ(std::atan2(1.0, 1.0) * 4.0, 3.14159265358979323846);
}

TEST(HarnessSmoke, FloatArithmetic) {
  const float x = g_xf;
  EXPECT_NEAR(std::sin(x) * std::sin(x) + std::cos(x) * std::cos(x), 1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(std::sqrt(4.0f * x * x), 2.0f * x);
}

TEST(HarnessSmoke, AssertStopsOnlyTheFailingTest) {
  ASSERT_TRUE(true);
  ASSERT_EQ(3, 3);
  ASSERT_NEAR(g_x, 0.5, 0.0);
}

}  // namespace
