// arbor: configuration macros and the library-wide assertion policy.
#pragma once

/// Library version, kept in sync with the CMake project version.
#define ARBOR_VERSION_MAJOR 0
#define ARBOR_VERSION_MINOR 1
#define ARBOR_VERSION_PATCH 0

/// Force-inline hint used on small hot functions of the unrolled recursions.
/// ARBOR_NOINLINE: never inlined (a rarely taken path kept out of its caller's inlining budget).
/// ARBOR_FLATTEN (a function, or a lambda after its parameter list): every call inside it is
/// inlined, whatever the compiler's inlining budget of the translation unit (static_for_flat).
/// Defining ARBOR_FLATTEN empty before any arbor header (e.g. -DARBOR_FLATTEN=) turns this off:
/// the same arithmetic, less compiler time and memory, the compiler's own inlining decisions
/// (the hosted unit tests do this; benchmarks and firmware keep it).
#if defined(__GNUC__) || defined(__clang__)
#define ARBOR_INLINE inline __attribute__((always_inline))
#define ARBOR_NOINLINE __attribute__((noinline))
#ifndef ARBOR_FLATTEN
#define ARBOR_FLATTEN __attribute__((flatten))
#endif
#else
#define ARBOR_INLINE inline
#define ARBOR_NOINLINE
#ifndef ARBOR_FLATTEN
#define ARBOR_FLATTEN
#endif
#endif

// ---------------------------------------------------------------------------------------------
// ARBOR_ASSERT(cond, msg): checks programming errors (wrong indices, bad sizes). Policy, chosen by
// defining ARBOR_ASSERT_POLICY before including any arbor header:
//   0  off: the condition is not evaluated (default when NDEBUG is defined)
//   1  on: a failed check calls ARBOR_ASSERT_HANDLER(file, line, expr, msg) (default otherwise)
// ARBOR_ASSERT_HANDLER defaults to __builtin_trap(); firmware may define it to a function of its
// own (log, then reset). It must not return. No exceptions and no I/O in the library itself.
// ---------------------------------------------------------------------------------------------
#ifndef ARBOR_ASSERT_POLICY
#ifdef NDEBUG
#define ARBOR_ASSERT_POLICY 0
#else
#define ARBOR_ASSERT_POLICY 1
#endif
#endif

#ifndef ARBOR_ASSERT_HANDLER
#define ARBOR_ASSERT_HANDLER(file, line, expr, msg) __builtin_trap()
#endif

#if ARBOR_ASSERT_POLICY == 0
#define ARBOR_ASSERT(cond, msg) ((void)0)
#else
#define ARBOR_ASSERT(cond, msg) \
  ((cond) ? (void)0 : (ARBOR_ASSERT_HANDLER(__FILE__, __LINE__, #cond, msg), (void)0))
#endif

namespace arbor {
/// Bytes of the SIMD register arbor's lane-parallel code fills (0: none): 32 with AVX (also under
/// AVX-512: the 64-byte registers are not used), 16 with SSE2 or NEON. Dual numbers pad their
/// directions to it (ad/expr/structure.hpp), the joints' sines and cosines are batched to it
/// (core/sincos_batch.hpp), generated stages run that many bytes of lanes (core/pack.hpp).
#if defined(__AVX__)
inline constexpr int simd_bytes = 32;
#elif defined(__SSE2__) || defined(__ARM_NEON)
inline constexpr int simd_bytes = 16;
#else
inline constexpr int simd_bytes = 0;
#endif
}  // namespace arbor
