// Deliberately failing: registered with WILL_FAIL, so the suite passes only when a failed check
// really makes the test executable exit non-zero on this target.
#include "arbor_test.hpp"

namespace {

volatile int g_two = 2;

TEST(HarnessFailure, OneCheckFails) {
  EXPECT_EQ(g_two + 2, 5) << "this failure is intended";
}

}  // namespace
