// Bare metal only, WILL_FAIL: a trap (what a failed eigen_assert or ARBOR_ASSERT executes) must
// reach the fault handler, which prints the fault registers and ends the program non-zero. A
// second CTest entry checks the report.
#include "arbor_test.hpp"

namespace {

volatile int g_zero = 0;

TEST(FaultTrap, TrapEndsTheProgramWithAFaultReport) {
  if (g_zero == 0)
    __builtin_trap();
  EXPECT_TRUE(false) << "not reached: the trap returned";
}

}  // namespace
