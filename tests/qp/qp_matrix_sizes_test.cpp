// The rest of the QP size matrix (qp_matrix_test.cpp says which sizes run where), in the host's
// default build (SSE2, the tests' -O1): a second translation unit of qp_matrix_test, compiled in
// parallel with the first (each ~3 GB of compiler memory instead of 5.5 GB together).
#include "isa.hpp"
#include "qp_matrix.hpp"

namespace {
using qp_matrix::check_size;
const char* const isa = arbor::test::isa_name();

TEST(QpMatrix, MoreOddSizesDouble) {
  check_size<double, 1, 1, 1, 0, 0, false>(100, 4, isa);
  check_size<double, 2, 13, 5, 1, 0, false>(600, 3, isa);
  check_size<double, 1, 15, 8, 0, 3, false>(700, 4, isa);
  check_size<double, 2, 17, 2, 4, 1, false>(800, 3, isa);
}
TEST(QpMatrix, Issue35CrashSizeFloat) {
  check_size<float, 20, 14, 7, 1, 1>(2500, 2, isa);
}
}  // namespace
