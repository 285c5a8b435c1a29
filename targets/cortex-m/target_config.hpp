// Force-included (-include) into every C++ translation unit of a bare-metal build.
// Eigen must never allocate (EIGEN_NO_MALLOC makes any attempt an assertion), and eigen_assert
// stays active under NDEBUG: a failed check ends the program with ARBOR_EXIT_ABORT.
#pragma once
#define EIGEN_NO_MALLOC
#define EIGEN_DONT_PARALLELIZE
#define eigen_assert(x) ((x) ? (void)0 : __builtin_trap())
