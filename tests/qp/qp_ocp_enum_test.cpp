// OCP-structured solver on random strictly and merely convex problems: KKT conditions (recomputed
// with dynamic Eigen), agreement with the dense variant and, for tiny sizes, with an exhaustive
// active-set enumeration written in the test.
#include "qp_ocp_check.hpp"

namespace {
using arbor::qp::test::check_random;
using arbor::qp::test::Convexity;

TEST(QpOcp, TinyStrictlyConvexMatchesEnumeration) {
  check_random<2, 2, 1, 1, 1>(100, 6, Convexity::strict, true);
}
TEST(QpOcp, TinyMerelyConvexMatchesEnumeration) {
  check_random<2, 2, 1, 1, 1>(200, 6, Convexity::merely, true);
}
TEST(QpOcp, SmallNoStageConstraintsMatchesEnumeration) {
  check_random<3, 2, 1, 0, 0>(300, 4, Convexity::strict, true);
}
TEST(QpOcp, TinyLinearProgramMatchesEnumeration) {
  check_random<2, 2, 1, 1, 1>(900, 6, Convexity::lp, true);
}
}  // namespace
