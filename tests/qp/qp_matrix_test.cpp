// The QP size matrix (qp_matrix.hpp), one executable per instruction set (tests/qp/CMakeLists.txt:
// SSE2 at the tests' -O1; -O3 with AVX2+FMA, AVX-512 (-march=native) and AVX-512 without Eigen's
// static alignment; NEON on AArch64, no SIMD on the Cortex-M targets): sizes chosen so that 1, 2,
// 3, 5, 7, 9, 13, 14, 15, 17 and multiples of 4 and 8 occur among nx, nu, ng and N, with nu = 1,
// ng = 0, ngn = 0 and N = 1 among them; the OCP solver in double and in float against the dense
// solver in double (sizes up to 100 variables) and a KKT check written in the test.
// (N, nx, nu, ng, ngn) = (20, 14, 7, 1, 1) is the QP of issue 35's segfault (-march=native,
// AVX-512: a 32-byte aligned store to an address 16 mod 32 in the Riccati solve).
// Each size costs ~20 s of compiler time at -O1 and several times that at -O3 with wide vectors
// (four sizes at -O3 -march=native: over 6 min and 3.4 GB): the -O3 variants
// (ARBOR_QP_MATRIX_SHORT) take the two cases where the vector width matters most (nx = 5 with
// nu = 9, and the crash size), in double; the default build and the targets take all of them.
#include "qp_matrix.hpp"
#include "isa.hpp"

namespace {
using qp_matrix::check_size;
const char* const isa = arbor::test::isa_name();

TEST(QpMatrix, PrintsTheInstructionSet) {
  arbor::test::print_isa();
}

// N, nx, nu, ng, ngn
TEST(QpMatrix, OddSizesDouble) {
  check_size<double, 3, 5, 9, 2, 1>(300, 4, isa);
#if !ARBOR_QP_MATRIX_SHORT
  check_size<double, 1, 1, 1, 0, 0>(100, 4, isa);
  check_size<double, 2, 13, 5, 1, 0>(600, 3, isa);
  check_size<double, 1, 15, 8, 0, 3>(700, 4, isa);
  check_size<double, 2, 17, 2, 4, 1>(800, 3, isa);
#endif
}
// Bare metal: the crash size (~0.2 MB of solver and KKT data per scalar) is left out.
#if !defined(ARBOR_BARE_METAL)
TEST(QpMatrix, Issue35CrashSizeDouble) {
  check_size<double, 20, 14, 7, 1, 1>(1300, 2, isa);
}
#endif
#if !ARBOR_QP_MATRIX_SHORT
#if !defined(ARBOR_BARE_METAL)
TEST(QpMatrix, Issue35CrashSizeFloat) {
  check_size<float, 20, 14, 7, 1, 1>(2500, 2, isa);
}
#endif
TEST(QpMatrix, OddSizesFloat) {
  check_size<float, 3, 3, 2, 1, 1>(2100, 4, isa);
}
#endif
}  // namespace
