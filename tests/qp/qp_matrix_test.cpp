// The QP size matrix (qp_matrix.hpp), one executable per instruction set (tests/qp/CMakeLists.txt:
// SSE2 at the tests' -O1 and at -O3, AVX2+FMA and AVX-512 at -O3; NEON on AArch64, no SIMD on the
// Cortex-M targets): sizes chosen so that 1, 2, 3, 5, 7, 9, 13, 14, 15, 17 and multiples of 4 and
// 8 occur as nx, nu, ng and N, with nu = 1, ng = 0, ngn = 0 and N = 1 among them; the OCP solver in
// double and in float against the dense solver in double and a KKT check written in the test.
// (N, nx, nu, ng, ngn) = (20, 14, 7, 1, 1) is the QP of issue 35's segfault (-march=native,
// AVX-512: a 32-byte aligned store to an address 16 mod 32 in the Riccati solve).
#include "qp_matrix.hpp"
#include "isa.hpp"

namespace {
using qp_matrix::check_size;
// Bare metal: the large sizes' dense reference (~2.6 MB of static memory) does not fit the RAM.
#if defined(ARBOR_BARE_METAL)
#define ARBOR_QP_MATRIX_LARGE 0
#else
#define ARBOR_QP_MATRIX_LARGE 1
#endif
const char* const isa = arbor::test::isa_name();

TEST(QpMatrix, PrintsTheInstructionSet) {
  arbor::test::print_isa();
}

// N, nx, nu, ng, ngn
TEST(QpMatrix, SmallSizesDouble) {
  check_size<double, 1, 1, 1, 0, 0>(100, 4, isa);
  check_size<double, 3, 2, 1, 1, 1>(200, 4, isa);
  check_size<double, 2, 3, 2, 0, 1>(300, 4, isa);
  check_size<double, 1, 5, 3, 2, 0>(400, 4, isa);
  check_size<double, 4, 7, 1, 1, 2>(500, 3, isa);
  check_size<double, 3, 9, 4, 3, 0>(600, 3, isa);
}
TEST(QpMatrix, VectorWidthSizesDouble) {
  check_size<double, 2, 4, 8, 4, 1>(700, 3, isa);
  check_size<double, 2, 8, 4, 1, 1>(800, 3, isa);
  check_size<double, 2, 13, 5, 1, 0>(900, 3, isa);
  check_size<double, 2, 15, 1, 2, 1>(1000, 3, isa);
  check_size<double, 2, 17, 9, 0, 3>(1100, 3, isa);
#if ARBOR_QP_MATRIX_LARGE
  check_size<double, 3, 16, 8, 1, 1>(1200, 2, isa);
  check_size<double, 20, 14, 7, 1, 1>(1300, 2, isa);  // issue 35's crash
#endif
}
TEST(QpMatrix, SizesFloat) {
  check_size<float, 1, 1, 1, 0, 0>(2100, 4, isa);
  check_size<float, 3, 3, 2, 1, 1>(2200, 4, isa);
  check_size<float, 2, 7, 3, 2, 1>(2300, 3, isa);
  check_size<float, 2, 13, 5, 1, 0>(2400, 3, isa);
#if ARBOR_QP_MATRIX_LARGE
  check_size<float, 20, 14, 7, 1, 1>(2500, 2, isa);
#endif
}
}  // namespace
