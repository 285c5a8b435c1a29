// The one include for portable tests: GoogleTest and the allocation guard on hosted builds, the
// minitest harness on bare metal (where every heap allocation already ends the program, so the
// guard scope is empty there).
#pragma once

#if defined(ARBOR_BARE_METAL)
#include <cstddef>

#include "minitest.hpp"
namespace arbor::test {
/// On bare metal the link-time heap trap replaces the guard: nothing can allocate and survive.
class NoAllocScope {
 public:
  NoAllocScope() {}
  std::size_t count() const { return 0; }
};
}  // namespace arbor::test
#else
#include <gtest/gtest.h>

#include "alloc_guard.hpp"
#endif
