// Bare metal only, WILL_FAIL: allocating must end the program through the heap trap. A second
// CTest entry checks the trap's message.
#include <cstdlib>

#include "arbor_test.hpp"

namespace {

TEST(HeapTrap, MallocEndsTheProgram) {
  void* volatile p = std::malloc(16);
  std::free(p);
  EXPECT_TRUE(false) << "not reached: malloc returned";
}

}  // namespace
