// The QP size matrix (qp_matrix.hpp), one executable per instruction set (tests/qp/CMakeLists.txt:
// SSE2 at the tests' -O1; -O3 with AVX2+FMA, AVX-512 (-march=native) and AVX-512 without Eigen's
// static alignment; NEON on AArch64, no SIMD on the Cortex-M targets): sizes chosen so that 1, 2,
// 3, 5, 7, 9, 13, 14, 15, 17 and multiples of 4 and 8 occur among nx, nu, ng and N, with nu = 1,
// ng = 0, ngn = 0 and N = 1 among them; the OCP solver in double and in float against the dense
// solver in double (padded to one size, up to 56 variables) and a KKT check written in the test.
// (N, nx, nu, ng, ngn) = (20, 14, 7, 1, 1) is the QP of issue 35's segfault (-march=native,
// AVX-512: a 32-byte aligned store to an address 16 mod 32 in the Riccati solve). Each problem of
// this file's sizes (and the float (20, 14, 7, 1, 1) of the other) is also solved by the
// interior-point cold start and its crossover (qp/ocp_interior_point.hpp).
// Compile cost: each size is one instantiation of the OCP solver, 20-45 s of compiler time (70 %
// of it the front end's template instantiation, so -O0 would not save it) and ~0.6 GB. So the
// sizes are spread over the builds:
//   this file (every build)   (3, 5, 9, 2, 1) double: nx = 5 against nu = 9, where the vector
//                              width matters most; (20, 14, 7, 1, 1) double on hosted builds;
//                              without ARBOR_QP_MATRIX_SHORT (the default build and the targets)
//                              also (3, 3, 2, 1, 1) float;
//   qp_matrix_sizes_test.cpp  the rest of the matrix, in the host's default build only.
#include "qp_matrix.hpp"
#include "isa.hpp"

namespace {
using qp_matrix::check_size;
const char* const isa = arbor::test::isa_name();

TEST(QpMatrix, PrintsTheInstructionSet) {
  arbor::test::print_isa();
}

TEST(QpMatrix, OddSizesDouble) {
  check_size<double, 3, 5, 9, 2, 1>(300, 4, isa);
}
#if !defined(ARBOR_BARE_METAL)
TEST(QpMatrix, Issue35CrashSizeDouble) {
  check_size<double, 20, 14, 7, 1, 1>(1300, 2, isa);
}
#endif
#if !ARBOR_QP_MATRIX_SHORT
TEST(QpMatrix, OddSizesFloat) {
  check_size<float, 3, 3, 2, 1, 1>(2100, 4, isa);
}
#endif
}  // namespace
