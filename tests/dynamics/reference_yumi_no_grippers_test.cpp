// YumiNoGrippers against the Pinocchio reference values (rnea, gravity, nle, crba, aba, minv, every
// frame).
#include <robots/yumi_no_grippers.hpp>

#include "reference_checks.hpp"

namespace {
using R = arbor::robots::YumiNoGrippers;
static_assert(arbor::Robot<R>);

TEST(Reference_YumiNoGrippers, MatchesPinocchio) {
  arbor::test::check_reference<R>("yumi_no_grippers", 1e-9);
}
}  // namespace
