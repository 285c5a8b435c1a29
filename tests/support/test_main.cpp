// Test support: GoogleTest main shared by every host test executable. Allocation checking is
// linked in through alloc_guard.cpp; tests open NoAllocScope around library calls.
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
