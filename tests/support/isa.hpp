// Test support: which instruction set a test executable was built for (the size matrix is built
// once per ISA the project claims: tests/qp and tests/nmpc CMakeLists), printed at the start of a
// run so a log says what was exercised, with Eigen's vector width and alignment.
#pragma once

#include <Eigen/Core>
#include <cstdio>
#include <cstdlib>

#include "test_log.hpp"

namespace arbor::test {

/// Name of the widest instruction set this translation unit was compiled for.
constexpr const char* isa_name() {
#if defined(__AVX512F__)
  return "AVX-512";
#elif defined(__AVX2__) && defined(__FMA__)
  return "AVX2+FMA";
#elif defined(__AVX__)
  return "AVX";
#elif defined(__ARM_NEON) || defined(__ARM_NEON__)
  return "NEON";
#elif defined(__SSE2__)
  return "SSE2";
#else
  return "no SIMD";
#endif
}

/// Prints the ISA, Eigen's SIMD sets and its static alignment, and the optimisation level. An
/// x86 executable built for AVX-512 or AVX2 on a CPU without it ends here with exit code 77
/// (CTest: SKIP_RETURN_CODE, a loud skip) before it runs any of those instructions in a test;
/// call it from the first test of the executable.
inline void print_isa() {
#if defined(__x86_64__) && (defined(__AVX512F__) || defined(__AVX2__))
#if defined(__AVX512F__)
  const bool ok = __builtin_cpu_supports("avx512f");
#else
  const bool ok = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif
  if (!ok) {
    std::printf("SKIPPED: built for %s, which this CPU lacks: nothing of it was tested here\n",
                isa_name());
    std::fflush(stdout);
    std::_Exit(77);  // (x86 hosted builds only)
  }
#endif
  log() << "instruction set: " << isa_name() << " (Eigen: " << Eigen::SimdInstructionSetsInUse()
        << "; EIGEN_MAX_STATIC_ALIGN_BYTES " << int(EIGEN_MAX_STATIC_ALIGN_BYTES) << "; "
#if defined(__OPTIMIZE__)
        << "optimised"
#else
        << "-O0"
#endif
        << ")\n";
}

}  // namespace arbor::test
