// Test support: detect heap allocations inside a scope.
//
//   {
//     arbor::test::NoAllocScope guard;   // from here on, any allocation is recorded
//     rnea<Robot>(data, q, v, a);
//   }                                     // the destructor fails the test if anything allocated
//
// Detection covers global operator new/delete (all forms), malloc, calloc, realloc, aligned_alloc,
// posix_memalign, memalign (interposed in the test executable), and Eigen's own run-time check
// (EIGEN_RUNTIME_NO_MALLOC, which makes Eigen assert on its first allocation).
#pragma once

#include <cstddef>

namespace arbor::test {

/// Number of allocations recorded on this thread while a guard was active.
std::size_t guarded_allocations();

/// RAII scope: enables allocation checking on this thread; on exit, reports a non-fatal gtest
/// failure naming the count when anything allocated inside the scope. Scopes may nest.
class NoAllocScope {
 public:
  NoAllocScope();
  ~NoAllocScope();
  NoAllocScope(const NoAllocScope&) = delete;
  NoAllocScope& operator=(const NoAllocScope&) = delete;

  /// Allocations recorded since this scope began.
  std::size_t count() const;

 private:
  std::size_t start_;
  bool eigen_was_allowed_;
};

}  // namespace arbor::test

/// Runs the statement inside a NoAllocScope: `ARBOR_EXPECT_NO_ALLOC(rnea<R>(d, q, v, a));`
#define ARBOR_EXPECT_NO_ALLOC(stmt)      \
  do {                                   \
    ::arbor::test::NoAllocScope guard__; \
    stmt;                                \
  } while (0)
