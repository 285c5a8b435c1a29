// OCP-structured solver on random strictly and merely convex problems: KKT conditions (recomputed
// with dynamic Eigen), agreement with the dense variant and, for tiny sizes, with an exhaustive
// active-set enumeration written in the test.
#include "qp_ocp_check.hpp"

namespace {
using arbor::qp::test::check_random;
using arbor::qp::test::Convexity;

TEST(QpOcp, RandomStrictlyConvexMatchesDense) {
  check_random<5, 3, 2, 2, 1>(400, 10, Convexity::strict, false);
  check_random<8, 4, 2, 1, 0>(500, 10, Convexity::strict, false);
  check_random<12, 2, 1, 1, 2>(600, 10, Convexity::strict, false);
}
TEST(QpOcp, RandomMerelyConvexMatchesDense) {
  check_random<5, 3, 2, 2, 1>(700, 10, Convexity::merely, false);
  check_random<8, 4, 2, 1, 0>(800, 10, Convexity::merely, false);
}
TEST(QpOcp, RandomLinearProgramMatchesDense) {
  check_random<6, 3, 2, 1, 1>(1000, 10, Convexity::lp, false);
}
}  // namespace
