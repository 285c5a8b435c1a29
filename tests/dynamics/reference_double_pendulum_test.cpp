// DoublePendulum against the Pinocchio reference values (rnea, gravity, nle, crba, aba, minv, every
// frame).
#include <robots/double_pendulum.hpp>

#include "reference_checks.hpp"

namespace {
using R = arbor::robots::DoublePendulum;
static_assert(arbor::Robot<R>);

TEST(Reference_DoublePendulum, MatchesPinocchio) {
  arbor::test::check_reference<R>("double_pendulum", 1e-9);
}
}  // namespace
