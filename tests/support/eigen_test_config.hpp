// Force-included (-include) into every test translation unit before anything else.
// Keeps Eigen's assertions active in optimized test builds, so EIGEN_RUNTIME_NO_MALLOC fires on
// the first Eigen heap allocation inside a NoAllocScope, and out-of-range indices trap.
#pragma once
#ifndef EIGEN_RUNTIME_NO_MALLOC
#define EIGEN_RUNTIME_NO_MALLOC
#endif
#define eigen_assert(x) ((x) ? (void)0 : __builtin_trap())
